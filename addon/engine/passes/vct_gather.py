"""VCT cone gathers through the radiance pyramid (gpu_shaders/vct/cone.glsl).

- pixels: at every G-buffer pixel, `diffuse_cones` cones about the normal -> `indirect` = E / pi
  (Cycles' Diffuse Indirect units) and `ao` (1 - cosine-weighted cone opacity). With
  VctConfig.gather_scale = s > 1 the cones run at one pixel per s x s block and an edge-aware
  upsampling (normal and tangent-plane weights) fills the full-size images.
- glossy: at every G-buffer pixel with a glossy lobe (Scene.specular > 0), VctConfig.specular_cones
  cones sampling the GGX lobe about the view's mirror direction, each as wide as its share of the lobe
  -> `glossy`, the light the lobe reflects to the camera (Cycles' Glossy Color x Glossy Indirect); the
  lobe's albedo comes from brdf.split_albedo_table().
- bounce: at every occupied voxel, the same gather (VctConfig.bounce_cones cones: the light it gathers
  is smooth, and every voxel pays two gathers) on both sides of its surface -> the next bounce's
  level-0 colours (premultiplied radiance by travel direction), albedo x E / pi x projected area.

Inputs: the pyramid (dict by direction), the Grid, VctConfig; G-buffer or the voxelizer's volumes.
"""

from __future__ import annotations

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from ..brdf import split_albedo_table
from ..config import VctConfig
from ..grid import Grid
from . import declare, surface_support
from .declare import (
    AO,
    GBUF_NORMAL,
    GBUF_POSITION,
    GBUF_SPECULAR,
    INDIRECT,
    VCT_PYRAMID,
    VOX_ALBEDO,
    VOX_NORMAL,
    VOX_PROJECTED,
    PassDecl,
)
from .vct_inject import DIRECTIONS
from .vct_pyramid import level_count, named, texture_size

_PYRAMID = tuple(Sampler(f"pyr_{d}", "3D") for d in DIRECTIONS)
_CONE_UNIFORMS = (Var("grid_origin", "vec3"), Var("cell_size", "float"), Var("dims", "ivec3"), Var("levels", "int"),
                  Var("tex_width", "int"), Var("step_ratio", "float"), Var("offset_cells", "float"),
                  Var("seed", "int"), Var("radiance_scale", "float"))
_DIFFUSE_UNIFORMS = (*_CONE_UNIFORMS, Var("diffuse_cones", "int"))

# Cone gathers run in 16 x 16 pixel work groups: on an H100 the 6-cone gather at 1080p took 2.35 ms at
# half resolution with 8 x 8 groups, 1.51 with 16 x 16 (16 x 8: 2.16, 32 x 8: 1.66; benchmarks/gpu): more
# neighbouring cones share the texture cache.
GATHER_GROUP = (16, 16, 1)

PIXELS = ShaderSpec(
    name="vct_gather",
    compute="vct/gather.comp.glsl",
    local_size=GATHER_GROUP,
    samplers=(*_PYRAMID, Sampler("gbuf_position", "2D"), Sampler("gbuf_normal", "2D"), Sampler("support", "2D")),
    images=(Image("indirect", "2D"), Image("ao", "2D")),
    uniforms=(*_DIFFUSE_UNIFORMS, Var("scale", "int"), Var("sample_index", "int"), Var("image_gathers", "int"),
              Var("support_gathers", "int"),
              Var("support_threshold", "float")),
)

UPSAMPLE = ShaderSpec(
    name="vct_upsample",
    compute="vct/upsample.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(Sampler("gbuf_position", "2D"), Sampler("gbuf_normal", "2D"), Sampler("low_indirect", "2D"),
              Sampler("low_ao", "2D")),
    images=(Image("indirect", "2D"), Image("ao", "2D")),
    uniforms=(Var("scale", "int"), Var("cell_size", "float")),
)

GLOSSY = ShaderSpec(
    name="vct_glossy",
    compute="vct/glossy.comp.glsl",
    local_size=GATHER_GROUP,
    samplers=(*_PYRAMID, Sampler("gbuf_position", "2D"), Sampler("gbuf_normal", "2D"),
              Sampler("gbuf_specular", "2D"), Sampler("split_albedo", "2D")),
    images=(Image("glossy", "2D"),),
    uniforms=(*_CONE_UNIFORMS, Var("camera_pos_ws", "vec3"), Var("specular_cones", "int"),
              Var("aperture_scale", "float"), Var("side_cap", "float")),
)

BOUNCE = ShaderSpec(
    name="vct_bounce",
    compute="vct/bounce.comp.glsl",
    local_size=(4, 4, 4),
    samplers=(*_PYRAMID, Sampler("vox_albedo", "3D"), Sampler("vox_normal", "3D"), Sampler("vox_projected", "3D")),
    images=tuple(Image(f"next_{d}", "3D") for d in DIRECTIONS),
    uniforms=_DIFFUSE_UNIFORMS,
)


PIXELS_DECL = PassDecl("vct_gather", "gather", (GBUF_POSITION, GBUF_NORMAL, surface_support.SUPPORT, VCT_PYRAMID),
                       (INDIRECT, AO),
                       "diffuse cones at every pixel")
GLOSSY_DECL = PassDecl("vct_glossy", "gather", (GBUF_POSITION, GBUF_NORMAL, GBUF_SPECULAR, VCT_PYRAMID),
                       (declare.GLOSSY,),
                       "specular cones over each glossy lobe")
BOUNCE_DECL = PassDecl("vct_bounce", "solve", (VCT_PYRAMID, VOX_ALBEDO, VOX_NORMAL, VOX_PROJECTED), (VCT_PYRAMID,),
                       "the next bounce gathered at the voxels")


def cone_uniforms(grid: Grid, config: VctConfig, seed: int, radiance_scale: float) -> dict:
    """`seed` turns every receiver's cone spiral by its own random angle (GIConfig.seed); radiance_scale
    is what the pyramid's radiance was multiplied by (vct_pyramid.radiance_scale)."""
    return {"seed": seed, "radiance_scale": radiance_scale, "grid_origin": grid.origin_m, "cell_size": grid.cell_size_m,
            "dims": grid.dims,
            "levels": level_count(grid.dims), "tex_width": texture_size(grid.dims)[0],
            "step_ratio": config.step_ratio,
            "offset_cells": config.offset_cells}


def low_size(size: tuple[int, int], scale: int) -> tuple[int, int]:
    """The gather's image size at 1/scale (rounded up: every pixel has a texel)."""
    return (-(-size[0] // scale), -(-size[1] // scale))


def pixels(backend: Backend, pyramid: dict, radiance_scale: float, gbuf: dict, support, indirect, ao, grid: Grid,
           config: VctConfig, seed: int = 0, low: tuple | None = None, sample: int = 0, image_samples: int = 1) -> None:
    """Gather into `indirect` and `ao`; with config.gather_scale > 1, into `low` (two textures of
    low_size) first, then upsample. `support` (surface_support's image of `gbuf`): pixels below its
    THRESHOLD gather config.support_gathers times as often; every pixel gathers `image_samples` times
    (surface_support.image_samples). `seed` is the update's; `sample` the gather's index among those
    averaged since (DirectMethod.sample_index): each pixel's cone pattern continues one low-discrepancy
    sequence over the samples (gather.comp.glsl)."""
    scale = config.gather_scale
    out = (indirect, ao) if scale == 1 else low
    backend.dispatch(backend.program(PIXELS), group_count(out[0].size, PIXELS.local_size),
                     uniforms={**cone_uniforms(grid, config, seed, radiance_scale),
                               "diffuse_cones": config.diffuse_cones, "scale": scale, "sample_index": sample,
                               "image_gathers": image_samples,
                               "support_gathers": config.support_gathers,
                               "support_threshold": surface_support.THRESHOLD},
                     samplers={**named(pyramid, "pyr"), "gbuf_position": gbuf["position"],
                               "gbuf_normal": gbuf["normal"], "support": support},
                     images={"indirect": out[0], "ao": out[1]})
    if scale > 1:
        upsample(backend, gbuf, low, indirect, ao, scale, grid.cell_size_m)


def upsample(backend: Backend, gbuf: dict, low: tuple, indirect, ao, scale: int, cell_size_m: float) -> None:
    """`low` (indirect, ao at 1/scale) -> `indirect`, `ao` at the G-buffer's size, along its edges."""
    backend.dispatch(backend.program(UPSAMPLE), group_count(indirect.size, UPSAMPLE.local_size),
                     uniforms={"scale": scale, "cell_size": cell_size_m},
                     samplers={"gbuf_position": gbuf["position"], "gbuf_normal": gbuf["normal"],
                               "low_indirect": low[0], "low_ao": low[1]},
                     images={"indirect": indirect, "ao": ao})


def split_albedo_texture(backend: Backend):
    """brdf.split_albedo_table() as a 2D texture sampled at (n.v, roughness)."""
    table = split_albedo_table()
    return backend.texture((table.shape[1], table.shape[0]), data=table)


def glossy(backend: Backend, pyramid: dict, radiance_scale: float, gbuf: dict, lobe_albedo, out, grid: Grid,
           config: VctConfig, camera_pos_m, seed: int = 0) -> None:
    """The specular cones at every pixel into `out` (G-buffer sized); `lobe_albedo` from
    split_albedo_texture; camera_pos_m in the G-buffer's frame."""
    backend.dispatch(backend.program(GLOSSY), group_count(out.size, GLOSSY.local_size),
                     uniforms={**cone_uniforms(grid, config, seed, radiance_scale), "camera_pos_ws": camera_pos_m,
                               "specular_cones": config.specular_cones, "aperture_scale": config.specular_aperture,
                               "side_cap": config.specular_side_cap},
                     samplers={**named(pyramid, "pyr"), "gbuf_position": gbuf["position"],
                               "gbuf_normal": gbuf["normal"], "gbuf_specular": gbuf["specular"],
                               "split_albedo": lobe_albedo},
                     images={"glossy": out})


def bounce(backend: Backend, pyramid: dict, radiance_scale: float, voxels: dict, next_bounce: dict, grid: Grid,
           config: VctConfig, seed: int = 0) -> None:
    backend.dispatch(backend.program(BOUNCE), group_count(grid.dims, BOUNCE.local_size),
                     uniforms={**cone_uniforms(grid, config, seed, radiance_scale),
                               "diffuse_cones": config.bounce_cones},
                     samplers={**named(pyramid, "pyr"), "vox_albedo": voxels["vox_albedo"],
                               "vox_normal": voxels["vox_normal"], "vox_projected": voxels["vox_projected"]},
                     images=named(next_bounce, "next"))
