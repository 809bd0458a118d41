"""Cone field `cone`'s constants (cone_fields.constants) as GLSL defines, compiled into the diffusion
step and emitters (diffusion/propagate.comp.glsl, emit.comp.glsl with CONES)."""

from __future__ import annotations

import functools

import numpy as np


def _vec4(v) -> str:
    return "vec4(" + ", ".join(f"{x:.9g}" for x in v) + ")"


def _mat4(m) -> str:
    return "mat4(" + ", ".join(f"{x:.9g}" for x in np.asarray(m).T.ravel()) + ")"  # GLSL takes columns


@functools.cache
def cone_defines(cone: int) -> tuple[tuple[str, str], ...]:
    """(name, value) pairs: CONES, CONE (the cone, 0..5 as the faces), its matrices and vectors as GLSL
    constructors, and EMIT_QUADRATURE."""
    from .. import cone_fields  # it imports diffusion_reference, which imports the diffusion passes

    k = cone_fields.constants()
    return (("CONES", "1"), ("CONE", str(cone)),
            ("CONE_MOVED", "mat4[6](" + ", ".join(_mat4(m) for m in k["moved"][cone]) + ")"),
            ("CONE_RAW", "vec4[6](" + ", ".join(_vec4(v) for v in k["raw"][cone]) + ")"),
            ("CONE_FLUX", _vec4(k["flux"][cone])), ("CONE_GRAM_INV", _mat4(k["gram_inv"][cone])),
            ("CONE_ISO", _vec4(k["iso"][cone])), ("EMIT_QUADRATURE", str(cone_fields.EMIT_QUADRATURE)))
