"""G-buffer pass: rasterize the scene from the camera.

Inputs: the scene's triangles (mesh attributes pos_ws, plane_ws (methods/direct.face_planes), normal_ws,
albedo, specular, and the Base Color texture's albedo_rect and albedo_uv: passes/albedo_atlas.py) and
the albedo atlas (sampler). Uniforms: view_projection, camera_pos_ws.
Outputs (RGBA32F, camera resolution, GL row 0 = bottom): position (world, m, on its triangle's plane;
w = 1 where geometry), normal (world, unit, flipped towards the camera), albedo (diffuse, linear: the
texel times the albedo attribute where the triangle has a texture, else that albedo), specular (rgb = the
glossy lobe's F0, a = roughness; Scene.specular). Depth: 32F.
"""

from __future__ import annotations

from ..backends.base import Backend, Sampler, ShaderSpec, Texture, Var
from ..scene import Camera
from . import zero
from .declare import ALBEDO_ATLAS, GBUFFER, TRIANGLES, PassDecl

SPEC = ShaderSpec(
    name="gbuffer",
    vertex="gbuffer/gbuffer.vert.glsl",
    fragment="gbuffer/gbuffer.frag.glsl",
    uniforms=(Var("view_projection", "mat4"), Var("camera_pos_ws", "vec3")),
    samplers=(Sampler("albedo_atlas", "2D"),),
    attributes=(Var("pos_ws", "vec3"), Var("plane_ws", "vec4"), Var("normal_ws", "vec3"), Var("albedo", "vec3"),
                Var("specular", "vec4"), Var("albedo_rect", "vec4"), Var("albedo_uv", "vec2")),
    varyings=(Var("v_pos_ws", "vec3"), Var("v_plane_ws", "vec4", "flat"), Var("v_normal_ws", "vec3"),
              Var("v_albedo", "vec3"), Var("v_specular", "vec4"), Var("v_albedo_rect", "vec4", "flat"),
              Var("v_albedo_uv", "vec2")),
    outputs=(Var("out_position", "vec4"), Var("out_normal", "vec4"), Var("out_albedo", "vec4"),
             Var("out_specular", "vec4")),
)


CHANNELS = tuple(port.name for port in GBUFFER)  # the outputs' textures, in order


DECL = PassDecl("gbuffer", "camera", (TRIANGLES, ALBEDO_ATLAS), GBUFFER, "the scene rasterized from the camera")


def run(backend: Backend, target, textures: dict, mesh, camera: Camera, albedo_atlas: Texture) -> None:
    """Draw into `target` (the CHANNELS textures of `textures` + depth); `albedo_atlas` from
    albedo_atlas.upload. The colours are zeroed by a compute pass and only depth by a clear: a
    framebuffer clear of four 1080p RGBA32F targets is raster work, slow on compute GPUs
    (passes/zero.py)."""
    zero.images(backend, [textures[c] for c in CHANNELS])
    backend.clear(target, color=None, depth=1.0)
    if mesh is not None:
        backend.draw(backend.program(SPEC), target, mesh,
                     uniforms={"view_projection": camera.view_projection, "camera_pos_ws": camera.position_m},
                     samplers={"albedo_atlas": albedo_atlas}, depth_test=True)
