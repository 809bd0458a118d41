"""Running mean of a product's gathers (gpu_shaders/common/running_mean.comp.glsl): progressive
refinement averages the n-th gather (another seed: other VPLs, other cone rotations) into the mean with
weight 1 / n, so the mean of n gathers has 1 / sqrt(n) of one gather's noise.

Inputs: `sample` (RGBA32F, image size: the latest gather), `mean` (RGBA32F, same size, read and written),
the weight. Units: the product's.
"""

from __future__ import annotations

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from .declare import INDIRECT, PassDecl

SPEC = ShaderSpec(
    name="running_mean",
    compute="common/running_mean.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(Sampler("sample_tex", "2D"),),
    images=(Image("mean", "2D", "RGBA32F", "read_write"),),
    uniforms=(Var("weight", "float"),),
)

DECL = PassDecl("accumulate", "gather", (INDIRECT,), (INDIRECT,),
                "a stochastic gather's products averaged over the samples so far (vct's ao and glossy too)")


def run(backend: Backend, sample, mean, weight: float) -> None:
    """mean := mean + (sample - mean) * weight."""
    backend.dispatch(backend.program(SPEC), group_count(mean.size, SPEC.local_size), uniforms={"weight": weight},
                     samplers={"sample_tex": sample}, images={"mean": mean})
