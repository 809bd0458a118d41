"""Declared passes: what each pass reads and writes, with formats and units, in one place.

Every pass module declares its pass(es) as `PassDecl`s built from the resources below (`Port`s). The
methods use the declarations three ways:
- they allocate the textures a pass writes from its declared outputs (`allocate`: format and extent),
- they time each pass under its declared name (`DirectMethod.step`),
- each method lists its passes per half of an update (`DirectMethod.PASSES`: camera, solve, gather),
  and a test checks that the list is what actually runs and that every input a pass reads is written
  by a pass before it (or is the scene's own: triangles, lights).

Extents: "image" is the G-buffer's size (camera pixels or lightmap texels), "rsm" a light face's RSM
(RsmConfig.resolution squared), "grid" a volume of grid.dims cells, "atlas" a grid's layers as tiles of
one 2D texture (passes/atlas.py), "pyramid" the VCT's levels side by side.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..backends.base import Backend

HALVES = ("setup", "camera", "solve", "gather")  # setup: once per geometry (set_scene)


@dataclass(frozen=True)
class Port:
    """One resource a pass reads or writes."""

    group: str      # what it belongs to: gbuffer, rsm, voxels, lpv, vct, product, scene
    name: str       # its key in that group's dict of textures (gbuffer: "position", ...)
    format: str     # backends.base.FORMATS key, or "mesh" / "uniforms" for scene inputs
    extent: str     # image, rsm, grid, atlas, pyramid, or scene
    units: str      # what its values are

    @property
    def key(self) -> str:
        return f"{self.group}.{self.name}"


@dataclass(frozen=True)
class PassDecl:
    name: str                   # the key its time is reported under
    half: str                   # HALVES: when it runs
    inputs: tuple[Port, ...]
    outputs: tuple[Port, ...]   # written (or added to) by the pass
    summary: str

    def __post_init__(self):
        if self.half not in HALVES:
            raise ValueError(f"pass {self.name}: half {self.half!r} is not one of {HALVES}")


def extend(passes: dict, **more) -> dict:
    """A method's pass lists (half -> passes) with `more` passes appended to the halves named."""
    unknown = set(more) - set(HALVES)
    if unknown:
        raise ValueError(f"no such half: {sorted(unknown)}")
    return {half: passes.get(half, ()) + tuple(more.get(half, ())) for half in HALVES}


def allocate(backend: Backend, ports, size) -> dict:
    """{port.name: texture} of `size` for the given ports, in their order (a target attaches them so)."""
    return {p.name: backend.texture(tuple(size), p.format) for p in ports}


def _image(group, name, units):
    return Port(group, name, "RGBA32F", "image", units)


# The scene's own inputs: uploaded by set_scene or passed as uniforms, written by no pass.
TRIANGLES = Port("scene", "triangles", "mesh", "scene", "world positions (m), normals, albedo, glossy lobe")
LIGHT_VIEWS = Port("scene", "light_views", "uniforms", "scene",
                   "per light face: view-projection, intensity (W/sr) or sun irradiance (W/m^2)")

OCCLUDERS = Port("scene", "occluders", "RGBA32F", "table",
                 "the corners (m) of the triangles the RSMs draw, OCCLUDER_ROW triangles of 3 texels per row")
BVH = Port("scene", "bvh", "RGBA32F", "table",
           "bvh.py's hierarchy over the occluders: node bounds (m) in heap order, triangles in leaf order")
ALBEDO_ATLAS = Port("scene", "albedo_atlas", "RGBA32F", "table",
                    "the Base Color images read per pixel (linear), packed by passes/albedo_atlas.py")
EMITTERS = Port("scene", "emitters", "RGBA32F", "table",
                "per polygon of an emitter with its shape: vertices (m), radiance (W/m^2/sr), sidedness")

GBUFFER = (_image("gbuffer", "position", "world position (m), w = 1 where geometry"),
           _image("gbuffer", "normal", "world normal (unit), towards the viewer"),
           _image("gbuffer", "albedo", "diffuse albedo (linear), w = 1 where geometry"),
           _image("gbuffer", "specular", "glossy lobe: rgb = F0, a = GGX roughness"))
GBUF_POSITION, GBUF_NORMAL, GBUF_ALBEDO, GBUF_SPECULAR = GBUFFER

RSM = (Port("rsm", "position", "RGBA32F", "rsm", "world position (m), w = 1 where geometry"),
       Port("rsm", "normal", "RGBA32F", "rsm", "world normal, facing the light; w = surfel area (m^2)"),
       Port("rsm", "flux", "RGBA32F", "rsm",
            "W reflected by the texel's surfel; w = 1 + index of the triangle it sees in the occluders (0: none)"))
RSM_POSITION, RSM_NORMAL, RSM_FLUX = RSM

DIRECT = _image("product", "direct", "irradiance / pi: Cycles' Diffuse Direct")
INDIRECT = _image("product", "indirect", "indirect irradiance / pi: Cycles' Diffuse Indirect")
AO = _image("product", "ao", "1 - cosine-weighted cone opacity")
GLOSSY = _image("product", "glossy", "W/m^2/sr the glossy lobes reflect: Glossy Color x Glossy Indirect")
VOXEL_VIEW = _image("product", "voxel_view", "debug colour: voxel albedo x checkerboard, magenta = hole")

VOXELS = (Port("voxels", "vox_albedo", "RGBA32F", "grid", "diffuse albedo, a = occupancy 0/1"),
          Port("voxels", "vox_normal", "RGBA32F", "grid", "mean normal, w = surface area (cells^2)"),
          Port("voxels", "vox_emission", "RGBA32F", "grid", "emitted radiance (W/m^2/sr), a = occupancy"),
          Port("voxels", "vox_projected", "RGBA32F", "grid", "area projected along each axis (cells^2)"),
          Port("voxels", "vox_offset", "RGBA32F", "grid", "surfaces' mean offset from the cell centre (cells)"))
VOX_ALBEDO, VOX_NORMAL, VOX_EMISSION, VOX_PROJECTED, VOX_OFFSET = VOXELS

LPV_ATLAS = Port("lpv", "inject_atlas", "RGBA32F", "atlas", "injected L1 SH of radiant intensity (W/sr), by layer tile")
LPV_SNAPSHOT = Port("lpv", "snapshots", "RGBA32F", "grid", "L1 SH of radiant intensity (W/sr) leaving each cell")
LPV_BLOCKING = Port("lpv", "blocking", "RGBA32F", "grid", "per axis the share of a cell's transfers blocked")
LPV_ACCUMULATED = Port("lpv", "accumulated", "RGBA32F", "grid",
                       "L1 SH (W/sr) summed over the propagation steps: the light field")

VCT_FLUX = Port("vct", "flux", "RGBA32F", "atlas", "per travel direction: VPL flux (W), a = surfel cross-section")
VCT_PYRAMID = Port("vct", "pyramid", "RGBA16F", "pyramid",
                   "per travel direction: premultiplied radiance x radiance_scale, a = opacity: the light field")
