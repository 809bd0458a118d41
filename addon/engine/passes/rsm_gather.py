"""RSM indirect gather pass (Dachsbacher & Stamminger 2005, eq. 1 with a disk term), no visibility.

Inputs: G-buffer position and normal; one RSM face's position, normal (w = surfel area, m^2) and flux
(W). Uniforms: strata_per_side (VPLs per pixel = strata_per_side^2), seed. Output: `indirect`
(RGBA32F, camera resolution), accumulated over faces and lights, in Cycles' Diffuse Indirect unit
(indirect irradiance / pi). One bounce. See gpu_shaders/rsm/gather.comp.glsl for the estimator.
"""

from __future__ import annotations

import math

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count

SPEC = ShaderSpec(
    name="rsm_gather",
    compute="rsm/gather.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(Sampler("gbuf_position", "2D"), Sampler("gbuf_normal", "2D"), Sampler("rsm_position", "2D"),
              Sampler("rsm_normal", "2D"), Sampler("rsm_flux", "2D")),
    images=(Image("indirect", "2D", "RGBA32F", "read_write"),),
    uniforms=(Var("strata_per_side", "int"), Var("seed", "int")),
)


def strata_per_side(vpl_samples: int) -> int:
    """VPLs are drawn one per block of a k x k split of the RSM: k = floor(sqrt(samples)), at least 1."""
    return max(1, math.isqrt(vpl_samples))


def run(backend: Backend, gbuf: dict, rsm: dict, indirect, vpl_samples: int, seed: int) -> None:
    backend.dispatch(
        backend.program(SPEC), group_count(indirect.size, SPEC.local_size),
        uniforms={"strata_per_side": strata_per_side(vpl_samples), "seed": seed},
        samplers={"gbuf_position": gbuf["position"], "gbuf_normal": gbuf["normal"],
                  "rsm_position": rsm["position"], "rsm_normal": rsm["normal"], "rsm_flux": rsm["flux"]},
        images={"indirect": indirect},
    )
