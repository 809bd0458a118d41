"""Bakes: a method's direct/indirect light per texel of an object's UV layout, or per mesh corner.

The light passes run unchanged on a *texel G-buffer* (bake_raster.py, passes/bake_gbuffer.py): the whole
scene is captured and uploaded once (RSMs, voxels), then each object's triangles are rasterized in UV
space into the method's G-buffer and shaded. Values are in Cycles' Diffuse Direct / Indirect units (a
Cycles DIFFUSE bake without the Color contribution); `combined` = direct + indirect (no albedo).

Images: float RGBA, row 0 = top (V = 1), alpha = coverage (1 where a triangle touches the texel), RGB
dilated `margin` texels past the coverage so seams do not bleed black when mip-mapped or filtered.
Vertex colours: one sample per (vertex, corner normal), written to a FLOAT_COLOR corner attribute.

Used by `python -m addon bake` (bake_file) and the BOUNCE_OT_bake operator (Baker directly).
"""

from __future__ import annotations

import json
import os
import sys
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import bpy
import numpy as np

from ..engine import choice, methods, registry
from ..engine.config import settings as complete_settings
from ..engine.errors import ConfigError, SceneError
from ..engine.lightmap import (
    IMAGE_SIZE_TEXELS,
    PASSES,
    TARGETS,
    VOLUME_TARGETS,
    block_mean,
    check_choice,
    check_supersample,
    dilate,
    output_path,
    safe_name,
    shard,
    uv_problems,
)
from ..engine.scene import Camera
from . import compat, images
from .bake_raster import TexelBaker
from .capture import SceneCache, define_light_switch, material_values

OVERLAP_WARN = 1e-3  # fraction of covered texels hit by more than one triangle


@dataclass
class ObjectResult:
    """What happened to one object: status ok | warning | skipped | error."""

    name: str
    status: str = "ok"
    message: str = ""
    file: str | None = None
    size: list[int] | None = None
    time_ms: float = 0.0
    solve_ms: float = 0.0   # of the light field: only the object whose bake solved it
    gather_ms: float = 0.0  # its texels' gather from the light field
    notes: list[str] = field(default_factory=list)
    self_check: dict | None = None  # bake --self-check: the path-traced estimate of this lightmap

    def to_dict(self) -> dict:
        return {"file": self.file, "size": self.size, "time_ms": round(self.time_ms, 2),
                "solve_ms": round(self.solve_ms, 2), "gather_ms": round(self.gather_ms, 2), "status": self.status,
                "message": self.message, "warnings": list(self.notes),
                **({"self_check": self.self_check} if self.self_check is not None else {})}

    def line(self) -> str:
        where = f" -> {self.file}" if self.file else ""
        size = f" {self.size[0]}x{self.size[1]}" if self.size else ""
        msg = f" ({self.message})" if self.message else ""
        return f"{self.status:7s} {self.name}{where}{size} {self.time_ms:.0f} ms{msg}"


# ------------------------------------------------------------------------------------------ object data

def _albedo_table(obj) -> np.ndarray:
    table = [material_values(s.material)[0] for s in obj.material_slots] or [material_values(None)[0]]
    return np.asarray(table, np.float64).reshape(-1, 3)


def _world(matrix: np.ndarray, pos: np.ndarray, nrm: np.ndarray, scale: float) -> tuple[np.ndarray, np.ndarray]:
    p = (pos @ matrix[:3, :3].T + matrix[:3, 3]) * scale
    n = nrm @ np.linalg.inv(matrix[:3, :3])  # inverse transpose, row vectors
    n /= np.maximum(np.linalg.norm(n, axis=-1, keepdims=True), 1e-30)
    return p, n  # a mirror flips the winding only; UV rasterization does not cull, so it does not matter


def _matrix(obj) -> np.ndarray:
    return np.array([list(r) for r in obj.matrix_world], np.float64)


def bake_uv_layer(mesh):
    """The UV map a bake uses: the active one (as Cycles' bake), else the active render one."""
    return mesh.uv_layers.active or next((u for u in mesh.uv_layers if u.active_render), None)


def object_triangles(obj, depsgraph) -> dict:
    """World triangles of the evaluated object with its bake UVs: uv (n, 3, 2), positions and corner
    normals (n, 3, 3) in metres, albedo (n, 3). Raises SceneError for non-meshes and meshes without UVs."""
    if obj.type != "MESH":
        raise SceneError(f"not a mesh (type {obj.type})")
    ev = obj.evaluated_get(depsgraph)
    mesh = ev.to_mesh()
    try:
        layer = bake_uv_layer(mesh)
        if layer is None:
            raise SceneError("no UV map: add one (UV > Smart UV Project) to bake")
        mesh.calc_loop_triangles()
        nt, nv, nl = len(mesh.loop_triangles), len(mesh.vertices), len(mesh.loops)
        co = np.empty(nv * 3, np.float64)
        mesh.vertices.foreach_get("co", co)
        tri_v, tri_l, mi = np.empty(nt * 3, np.int64), np.empty(nt * 3, np.int64), np.empty(nt, np.int64)
        mesh.loop_triangles.foreach_get("vertices", tri_v)
        mesh.loop_triangles.foreach_get("loops", tri_l)
        mesh.loop_triangles.foreach_get("material_index", mi)
        cn = np.empty(nl * 3, np.float64)
        mesh.corner_normals.foreach_get("vector", cn)
        uv = np.empty(nl * 2, np.float64)
        layer.uv.foreach_get("vector", uv)
    finally:
        ev.to_mesh_clear()
    scale = depsgraph.scene.unit_settings.scale_length or 1.0
    pos, nrm = _world(_matrix(ev), co.reshape(-1, 3)[tri_v].reshape(nt, 3, 3),
                      cn.reshape(-1, 3)[tri_l].reshape(nt, 3, 3), scale)
    table = _albedo_table(obj)
    return {"uv": uv.reshape(-1, 2)[tri_l].reshape(nt, 3, 2), "positions": pos, "normals": nrm,
            "albedo": table[np.clip(mi, 0, len(table) - 1)]}


def object_corners(obj, scale: float) -> dict:
    """Samples for a vertex-colour bake of the object's own mesh (modifiers not applied): one per
    distinct (vertex, corner normal); `corner_sample` maps each corner to its sample."""
    if obj.type != "MESH":
        raise SceneError(f"not a mesh (type {obj.type})")
    mesh = obj.data
    nv, nl, npoly = len(mesh.vertices), len(mesh.loops), len(mesh.polygons)
    if nl == 0:
        raise SceneError("the mesh has no faces")
    co = np.empty(nv * 3, np.float64)
    mesh.vertices.foreach_get("co", co)
    lv = np.empty(nl, np.int64)
    mesh.loops.foreach_get("vertex_index", lv)
    cn = np.empty(nl * 3, np.float64)
    mesh.corner_normals.foreach_get("vector", cn)
    totals, mi = np.empty(npoly, np.int64), np.empty(npoly, np.int64)
    mesh.polygons.foreach_get("loop_total", totals)
    mesh.polygons.foreach_get("material_index", mi)
    corner_mi = np.repeat(mi, totals)
    cn = cn.reshape(-1, 3)
    key = np.column_stack([lv, np.round(cn * 1e4).astype(np.int64), corner_mi])
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    pos, nrm = _world(_matrix(obj), co.reshape(-1, 3)[lv[first]], cn[first], scale)
    table = _albedo_table(obj)
    return {"positions": pos, "normals": nrm, "albedo": table[np.clip(corner_mi[first], 0, len(table) - 1)],
            "corner_sample": inverse.ravel()}


# ------------------------------------------------------------------------------------------------ baker

def pass_values(products: dict, pass_name: str) -> np.ndarray:
    """(..., 4) direct, indirect or combined = direct + indirect; alpha = coverage."""
    if pass_name == "direct":
        return products["direct"]
    if "indirect" not in products:
        raise ConfigError(f"pass {pass_name} needs an indirect method (rsm, lpv), not direct")
    if pass_name == "indirect":
        return products["indirect"]
    out = products["direct"].copy()
    out[..., :3] += products["indirect"][..., :3]
    return out


# Cycles' DIFFUSE bake filter for each pass (light alone, without the Color contribution)
CYCLES_PASS_FILTER = {"indirect": {"INDIRECT"}, "direct": {"DIRECT"}, "combined": {"DIRECT", "INDIRECT"}}
def bake_check_render(obj_name: str, pass_name: str, size: int, bounces: int):
    """choice.path_traced_check's `render` for one object's lightmap: Cycles' own bake of the same pass
    (reference.cycles_bake, the object's active UV map as ours), covering the texels its triangles touch."""
    from .reference import cycles_bake

    def render(spp: int, seed: int) -> tuple[np.ndarray, np.ndarray, float]:
        rgba, seconds = cycles_bake(obj_name, CYCLES_PASS_FILTER[pass_name], spp, seed, size, bounces)
        return rgba[..., :3], rgba[..., 3] > 0.5, seconds
    return render


def cycles_bakes(obj) -> bool:
    """Whether Cycles bakes the object: every material slot holds a node material."""
    return bool(obj.material_slots) and all(slot.material and compat.uses_nodes(slot.material)
                                            for slot in obj.material_slots)


def self_check(obj, values: np.ndarray, pass_name: str, size: int, bounces: int) -> dict:
    """bake --self-check of one lightmap (`values`, RGBA, alpha = coverage): its rel_rmse_8 against Cycles'
    converged bake, estimated by choice's path-traced check of the object, as precise as the error its
    pilot finds asks; a note where it cannot be made."""
    if not cycles_bakes(obj):
        return {"note": "no self-check: Cycles bakes only objects whose every material slot has a node material"}
    check = choice.path_traced_check(None, bake_check_render(obj.name, pass_name, size, bounces), ours=values)
    estimate = choice.path_traced_estimate(values, check) if check is not None else None
    if estimate is None:
        return {"note": "no self-check: no texel lit in both bakes"}
    return {"estimated_rel_rmse_8": estimate, **choice.check_stats(check)}


def _default_camera(size: int) -> Camera:
    return Camera(view=np.eye(4), projection=np.eye(4), width=size, height=size)


class Baker:
    """The scene captured and uploaded once; then bake_image / bake_vertex_colors per object."""

    def __init__(self, backend, depsgraph, settings: dict, size: int = 512, budget: dict | None = None):
        """settings: {group: config} (config.settings' form; missing groups take their defaults).
        budget ({"error_budget": E} or {"time_budget_ms": T}): the method chosen for the scene
        (engine/choice.py); `settings` and `decided` say what was run and why."""
        t0 = time.perf_counter()
        define_light_switch()
        self.backend = backend
        self.depsgraph = depsgraph
        scene = SceneCache().update(depsgraph, size, size)
        if scene.camera is None:
            scene.camera = _default_camera(size)  # only the G-buffer size is taken from it
        self.scene = scene
        settings, self.decided = choice.decide(scene, complete_settings(**settings), size * size, **(budget or {}))
        self.use(settings)
        self.setup_ms = (time.perf_counter() - t0) * 1e3

    def use(self, settings: dict) -> None:
        """Bake with `settings` from now on: their method made on the captured scene."""
        self.settings = settings
        self.method = methods.create(self.backend, settings)
        self.method.set_scene(self.scene)
        self.texels = TexelBaker(self.method)

    def bake_image(self, obj, size: int, pass_name: str, margin: int = 16,
                   supersample: int = 1) -> tuple[np.ndarray, list[str]]:
        """(h, w, 4) float32, row 0 = top, alpha = coverage, and warnings. supersample: sub-texels per
        texel side, each texel the mean of its covered ones (lightmap.block_mean)."""
        tri = object_triangles(obj, self.depsgraph)
        notes = uv_problems(tri["uv"], tri["positions"])
        args = (tri["uv"], tri["positions"], tri["normals"], tri["albedo"])
        overlap = self.texels.overlap(*args, (size, size))
        if overlap > OVERLAP_WARN:
            notes.append(f"overlapping UVs: {overlap:.1%} of covered texels belong to several triangles")
        fine = size * supersample
        values = block_mean(pass_values(self.texels.bake_triangles(*args, (fine, fine)), pass_name), supersample)
        covered = values[..., 3] > 0.5
        if not covered.any():
            notes.append("no texel covered (all UV triangles have zero area or lie outside 0..1)")
        rgb, _ = dilate(values[..., :3], covered, margin)
        return np.concatenate([rgb, covered[..., None].astype(np.float32)], axis=2), notes

    def bake_vertex_colors(self, obj, pass_name: str) -> tuple[np.ndarray, list[str]]:
        """(corners, 4) float32 colours for obj.data's corners, and warnings."""
        notes = []
        if any(m.show_render for m in obj.modifiers):
            notes.append("modifiers are not applied: colours are computed on the base mesh")
        if obj.data.users > 1:
            notes.append(f"mesh {obj.data.name!r} is shared by {obj.data.users} users: the last bake wins")
        scale = self.depsgraph.scene.unit_settings.scale_length or 1.0
        c = object_corners(obj, scale)
        values = pass_values(self.texels.bake_points(c["positions"], c["normals"], c["albedo"]), pass_name)
        out = values[c["corner_sample"]].astype(np.float32)
        out[:, 3] = 1.0
        return out, notes


# bake --verify judges its candidates on the VERIFY_OBJECTS largest objects baked (by surface: where most
# of the lightmaps' texels lie), each lightmap at most VERIFY_MAX_TEXELS a side: every object judged costs
# a Cycles check pair of its own, and the check's samples per texel do not fall as the texels grow (the
# model was fitted on 128 px images, 16 384 pixels; a 128 x 128 lightmap holds as many texels).
VERIFY_OBJECTS = 3
VERIFY_MAX_TEXELS = 128


def judged_objects(names: list[str], depsgraph) -> list:
    """The objects bake --verify judges: of `names`, the meshes with a bake UV map that Cycles bakes
    (cycles_bakes), the VERIFY_OBJECTS largest by world surface area."""
    found = []
    for name in names:
        obj = bpy.data.objects.get(name)
        if obj is None or obj.type != "MESH" or bake_uv_layer(obj.data) is None or not cycles_bakes(obj):
            continue
        pos = object_triangles(obj, depsgraph)["positions"]
        area_m2 = 0.5 * float(np.linalg.norm(np.cross(pos[:, 1] - pos[:, 0], pos[:, 2] - pos[:, 0]), axis=1).sum())
        found.append((area_m2, name, obj))
    return [obj for _, _, obj in sorted(found, key=lambda f: (-f[0], f[1]))[:VERIFY_OBJECTS]]


def verify_bake(baker: Baker, requested: dict, names: list[str], error_budget: float, size: int, say) -> None:
    """bake --verify: choice.verify's candidates baked on the judged objects (judged_objects) at
    min(size, VERIFY_MAX_TEXELS) texels, each lightmap judged by its object's path-traced check of the
    indirect light (resolving `error_budget`). A row's estimate is the largest of its lightmaps': the
    budget holds for every lightmap judged. The baker is left on the row taken (choice.take_verified:
    the first within the budget, else the least estimated), its `decided` listing the rows tried and the
    checks."""
    model = choice.load()
    feats = baker.decided["features"]
    texels = min(size, VERIFY_MAX_TEXELS)
    bounces = requested["gi"].bounces
    checks = {}
    for obj in judged_objects(names, baker.depsgraph):
        say(f"bake verify: the path-traced check of {obj.name}")
        check = choice.path_traced_check(error_budget, bake_check_render(obj.name, "indirect", texels, bounces), say)
        if check is not None:
            checks[obj.name] = (obj, check)
    if not checks:
        baker.decided["choice"]["verified"] = {
            "tried": [], "accepted": None,
            "note": "not verified: no object baked has a UV map, node materials and light in Cycles' bake"}
        return

    def estimate(key: str) -> float | None:
        say(f"bake verify: baking {key}")
        row = model.rows[key]
        baker.use(choice.apply_row(requested, row["method"], row["setting"]))
        found = [choice.path_traced_estimate(baker.bake_image(obj, texels, "indirect")[0], check)
                 for obj, check in checks.values()]
        found = [f for f in found if f is not None]
        return max(found) if found else None

    chosen = baker.settings
    accepted, tried = choice.verify(model, feats, error_budget, estimate, registry.computing(bounces))
    settings, baker.decided = choice.take_verified(
        model, feats, requested, chosen, baker.decided, error_budget, accepted, tried,
        {"texels": texels, "objects": {name: choice.check_stats(check) for name, (_, check) in checks.items()}})
    baker.use(settings)


# ------------------------------------------------------------------------------------- Blender outputs

def image_name(obj_name: str, pass_name: str) -> str:
    return f"{obj_name}_bounce_{pass_name}"


def store_image(name: str, rgba: np.ndarray):
    """A float Blender image `name` holding rgba (row 0 = top), packed into the .blend and kept by it: a
    new image has no users until a material reads it, and Blender drops datablocks without users when
    it saves, so the bake gets a fake user (the user clears it to let the image go)."""
    h, w = rgba.shape[:2]
    img = bpy.data.images.get(name)
    if img is not None and (tuple(img.size) != (w, h) or not img.is_float):
        bpy.data.images.remove(img)
        img = None
    if img is None:
        img = bpy.data.images.new(name, w, h, alpha=True, float_buffer=True)
    img.colorspace_settings.name = "Linear Rec.709" if "Linear Rec.709" in _colorspaces(img) else \
        img.colorspace_settings.name
    img.pixels.foreach_set(np.ascontiguousarray(rgba[::-1], np.float32).ravel())  # Blender: row 0 = bottom
    img.file_format = "OPEN_EXR"
    img.pack()
    img.use_fake_user = True
    return img


def _colorspaces(img) -> set[str]:
    return {item.identifier for item in img.colorspace_settings.bl_rna.properties["name"].enum_items}


def store_vertex_colors(mesh, name: str, colors: np.ndarray):
    """A FLOAT_COLOR corner attribute `name` on `mesh` (replaced if present)."""
    old = mesh.color_attributes.get(name)
    if old is not None:
        mesh.color_attributes.remove(old)
    attr = mesh.color_attributes.new(name, "FLOAT_COLOR", "CORNER")
    attr.data.foreach_set("color", np.ascontiguousarray(colors, np.float32).ravel())
    return attr


def attribute_name(pass_name: str) -> str:
    return f"bounce_{pass_name}"


# ------------------------------------------------------------------------------------- nothing baked

def empty_light_warning(scene) -> str | None:
    """Why every value baked from the captured engine Scene would be zero, or None: no light with
    power > 0, no emissive triangle and a black world."""
    if scene.has_light_source():
        return None
    return ("the scene has no light sources (no light with power > 0, no emissive surface, a black world): "
            "every baked value is zero")


ZERO_LIGHT = "no light: every baked value is zero"


def zero_light_warning(values: np.ndarray) -> str | None:
    """A warning when an object's bake holds no light where it is covered (values (..., 4), alpha =
    coverage; vertex colours: alpha 1), or None. Its objects are lit by nothing this pass computes."""
    covered = values[..., 3] > 0.5
    if covered.any() and not np.any(values[..., :3][covered] != 0):
        return ZERO_LIGHT
    return None


# ----------------------------------------------------------------------------------------- command line

def check_output_dir(out: Path) -> Path:
    """DIR exists (or is created, its parent existing) and is writable; else SceneError (exit 2)."""
    try:
        out.mkdir(exist_ok=True)
    except OSError as exc:
        raise SceneError(f"cannot use output directory {out}: {exc.strerror}") from None
    if not out.is_dir():
        raise SceneError(f"output path {out} is not a directory")
    probe = out / f".bounce_write_test_{os.getpid()}"
    try:
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as exc:
        raise SceneError(f"output directory {out} is not writable: {exc.strerror}") from None
    return out


def select_objects(names: list[str] | None, shard_index: int = 0, shard_count: int = 1) -> list[str]:
    """The names to bake: the given ones, or every mesh object in the scene; then the shard."""
    if names is None:
        names = [o.name for o in bpy.context.scene.objects if o.type == "MESH"]
    return shard(set(names), shard_index, shard_count)


def bake_file(blend: Path, out_dir: Path, objects: list[str] | None = None, size: int | None = None,
              settings: dict | None = None, pass_name: str = "indirect",
              target: str = "image", overwrite: bool = False, shard_index: int = 0, shard_count: int = 1,
              save_blend: Path | None = None, margin: int = 16, progress: bool = True, backend=None,
              budget: dict | None = None, supersample: int = 1, self_check: bool = False,
              verify: bool | None = None) -> dict:
    """Bake the objects of `blend` (see module docstring) into out_dir; returns the summary written to
    out_dir/bake.json. Per-object problems are recorded, never raised; bad arguments raise BounceError.
    size: the lightmap side (IMAGE_SIZE_TEXELS when None). settings: {group: config} (config.settings'
    form; defaults for missing groups). budget: the method chosen for the scene (Baker). supersample:
    sub-texels per texel side of --target image (Baker.bake_image). self_check (--target image): each
    lightmap's error against Cycles' converged bake estimated by the path-traced check (`self_check`),
    in its object's entry. verify (an error budget, --target image; None: on exactly there): the choice
    checked on the objects before they are baked (verify_bake; bake.json choice.verified). A bake that
    yields no light is recorded under "warnings" and told on stderr."""
    from .pipeline import backend as default_backend
    from .pipeline import open_blend

    check_choice(pass_name, PASSES, "--pass")
    check_choice(target, TARGETS, "--target")
    if target in VOLUME_TARGETS:
        raise ConfigError(f"--target {target} is one per scene, not per object: use bake_volume / bake_probes")
    if self_check and target != "image":
        raise ConfigError("--self-check judges lightmap images (--target image): Cycles bakes no vertex colours")
    error_budget = (budget or {}).get("error_budget")
    if verify and (error_budget is None or target != "image"):
        raise ConfigError("--verify checks the choice for an error budget on lightmap images: give --method auto "
                          "--error-budget E with --target image")
    verify = error_budget is not None and target == "image" if verify is None else verify
    size = IMAGE_SIZE_TEXELS if size is None else size
    if not 8 <= size <= 8192:
        raise ConfigError(f"--size must be in 8..8192, got {size}")
    check_supersample(supersample, size)
    settings = complete_settings(**(settings or {}))
    gi = settings["gi"]
    out_dir = check_output_dir(Path(out_dir))
    if save_blend is not None and Path(save_blend).resolve() == Path(blend).resolve():
        raise ConfigError("--save-blend must not be the input file (the .blend is never modified)")
    say = _stderr_lines(progress)
    say(f"bake: opening {blend}")
    open_blend(blend)
    names = select_objects(objects, shard_index, shard_count)
    if not names:
        raise SceneError(f"{blend}: no objects to bake" + (" in this shard" if shard_count > 1 else ""))
    t0 = time.perf_counter()
    be = backend or default_backend()
    say(f"bake: capturing the scene, method {gi.method} setup")
    baker = Baker(be, bpy.context.evaluated_depsgraph_get(), settings, size, budget)
    verify_ms = 0.0
    if verify:
        t_verify = time.perf_counter()
        verify_bake(baker, settings, names, error_budget, size, say)
        verify_ms = (time.perf_counter() - t_verify) * 1e3
    settings, gi = baker.settings, baker.settings["gi"]
    results = _bake_objects(baker, names, out_dir, size, pass_name, target, overwrite, margin, progress,
                            supersample, self_check)
    saved = None
    if save_blend is not None and target == "vertex-colors":
        bpy.ops.wm.save_as_mainfile(filepath=str(save_blend), copy=True, compress=False)
        saved = str(save_blend)
    warnings = _file_warnings(baker.scene, results)
    for warning in warnings:
        print(f"warning: {Path(blend).name}: {warning}", file=sys.stderr)
    summary = {
        "blend": str(blend), "method": gi.method, "pass": pass_name, "target": target, "size": size,
        "supersample": supersample,
        "config": {group: config.to_dict() for group, config in settings.items()}, "renderer": be.renderer,
        "setup_ms": round(baker.setup_ms, 2), "verify_ms": round(verify_ms, 2),
        "total_ms": round((time.perf_counter() - t0) * 1e3, 2),
        "shard": [shard_index, shard_count], "saved_blend": saved, "solves": baker.method.solves,
        **{k: v for k, v in baker.decided.items() if k != "features"},
        "scene_warnings": list(baker.scene.warnings), "warnings": warnings,
        "objects": {r.name: r.to_dict() for r in results},
    }
    (out_dir / "bake.json").write_text(json.dumps(summary, indent=2))
    return summary


def _stderr_lines(enabled: bool):
    """print() to stderr when enabled (progress), else a no-op."""
    if not enabled:
        return lambda line: None
    return lambda line: print(line, file=sys.stderr, flush=True)


def _bake_objects(baker: Baker, names: list[str], out_dir: Path, size: int, pass_name: str, target: str,
                  overwrite: bool, margin: int, progress: bool, supersample: int = 1,
                  checked: bool = False) -> list[ObjectResult]:
    from tqdm import tqdm

    results, taken = [], set()
    bar = tqdm(names, desc="bake", unit="obj", file=sys.stderr, disable=not progress)
    for name in bar:
        bar.set_postfix_str(name[:30])
        res = _bake_one(baker, name, out_dir, size, pass_name, target, overwrite, margin, taken, supersample,
                        checked)
        results.append(res)
        tqdm.write(res.line(), file=sys.stdout)
    return results


def _file_warnings(scene, results: list[ObjectResult]) -> list[str]:
    """The file's warnings: a scene without light, or a run that baked nothing (failures are errors,
    told as such)."""
    warnings = [w for w in [empty_light_warning(scene)] if w]
    if all(r.status == "skipped" for r in results):
        warnings.append("nothing baked: every object's file exists (use --overwrite)")
    dark = [r.name for r in results if ZERO_LIGHT in r.notes]
    if dark and not warnings:  # the scene is lit, yet these objects receive none of this pass's light
        warnings.append(f"{len(dark)} object(s) baked no light: {', '.join(dark)}")
    return warnings


def _bake_one(baker: Baker, name: str, out_dir: Path, size: int, pass_name: str, target: str, overwrite: bool,
              margin: int, taken: set[str], supersample: int = 1, checked: bool = False) -> ObjectResult:
    """Bake one object; `checked` (bake --self-check): also its path-traced estimate (self_check)."""
    res = ObjectResult(name)
    t0 = time.perf_counter()
    try:
        obj = bpy.data.objects.get(name)
        if obj is None:
            raise SceneError("no such object")
        if target == "image":
            path = output_path(out_dir, name, pass_name, taken)
            res.file = str(path)
            if path.exists() and not overwrite:
                res.status, res.message = "skipped", "file exists (use --overwrite)"
                return res
            values, notes = baker.bake_image(obj, size, pass_name, margin, supersample)
            images.write_exr(path, values)
            res.size = [size, size]
            if checked:
                res.self_check = self_check(obj, values, pass_name, size, baker.settings["gi"].bounces)
        else:
            values, notes = baker.bake_vertex_colors(obj, pass_name)
            store_vertex_colors(obj.data, attribute_name(pass_name), values)
            res.file = f"{obj.data.name}:{attribute_name(pass_name)}"
            res.size = [len(values), 1]
        res.solve_ms = baker.texels.last_timings.get("solve", 0.0)
        res.gather_ms = baker.texels.last_timings.get("gather", 0.0)
        res.notes = notes + [w for w in [zero_light_warning(values)] if w]
        if res.notes:
            res.status, res.message = "warning", "; ".join(res.notes)
    except (SceneError, ConfigError) as exc:
        res.status, res.message = "error", str(exc)
    finally:
        res.time_ms = (time.perf_counter() - t0) * 1e3
    return res


def bake_volume(blend: Path, out_dir: Path, settings: dict, overwrite: bool = False,
                backend=None, progress: bool = True) -> dict:
    """The LPV's indirect light of the whole scene as a volume for engines: DIR/<stem>_lpv_sh.npz.

    Layout (numpy .npz): `sh_r`, `sh_g`, `sh_b` float32 (z, y, x, 4) — per colour, L1 SH in the order
    (1, y, z, x) of the radiant intensity (W/sr) of the light that passed through each cell by direction
    of travel, summed over the propagation steps (docs/LPV.md, "What a cell stores"); `origin_m` (3,)
    world position of the grid's corner (cell (0, 0, 0) spans origin .. origin + cell_size_m);
    `cell_size_m` scalar; `dims` (3,) x, y, z. To light a surface with normal n at p: sample the SH
    trilinearly at p + 0.5 cell n (cell centres at origin + (i + 0.5) cell), E = max(0, c . lobe(-n)) /
    cell_size_m^2 with lobe(m) = (0.886227, 1.023327 m.y, m.z, m.x); Cycles' Diffuse Indirect = E / pi.
    With the geometry volume on (LpvConfig's default) the file also holds `vox_normal` float32
    (z, y, x, 4): per cell the voxelized surfaces' mean normal (xyz) and area in cells^2 (w); each of
    the 8 trilinear corners is then weighted by 1 - min(1, w |n_cell . n|) and the weights renormalised
    (plain trilinear where all are 0): a cell holding a surface facing the receiver holds light its own
    geometry half-blocked (docs/LPV.md, "Lookup"). The finest cascade is written when there are several.
    """
    settings = complete_settings(**settings)
    gi = settings["gi"]
    if gi.method != "lpv":
        raise ConfigError(f"--target volume bakes the LPV's grid: use --method lpv (got {gi.method})")
    out_dir = check_output_dir(Path(out_dir))
    path = out_dir / f"{safe_name(Path(blend).stem)}_lpv_sh.npz"
    if path.exists() and not overwrite:
        raise SceneError(f"{path} exists (use --overwrite)")
    t0 = time.perf_counter()
    be, scene, method = _scene_without_camera(blend, settings, backend, _stderr_lines(progress),
                                              "capturing the scene, propagating the LPV")
    timings = method.solve_volume()
    sh = {f"sh_{c}": be.read(method.accumulated[f"acc_{c}"]) for c in "rgb"}
    grid = method.grid
    extra = {} if method.vox_normal is None else {"vox_normal": be.read(method.vox_normal)}
    np.savez_compressed(path, **sh, **extra, origin_m=grid.origin_m + method.origin_m,
                        cell_size_m=grid.cell_size_m, dims=np.array(grid.dims))
    summary = {"blend": str(blend), "file": str(path), "dims": list(grid.dims), "cell_size_m": grid.cell_size_m,
               "time_ms": round((time.perf_counter() - t0) * 1e3, 2), "config": {"lpv": method.lpv_config.to_dict()},
               "solves": method.solves, "solve_ms": round(timings["solve"], 2),
               "warnings": _volume_warnings(blend, scene)}
    print(f"{Path(blend).name}: volume {grid.dims[0]}x{grid.dims[1]}x{grid.dims[2]} -> {path}")
    return summary


def bake_probes(blend: Path, out_dir: Path, settings: dict, overwrite: bool = False,
                backend=None, progress: bool = True) -> dict:
    """Method `probes`' solved probe volume for engines (engine/probe_export.py; docs/BAKE.md):
    DIR/<stem>_probes.json (the layout: grid, faces, tiles, units, files) and six EXR textures,
    <stem>_probes_sh.exr, <stem>_probes_irradiance.exr, <stem>_probes_moments.exr,
    <stem>_probes_offsets.exr (the probes' relocation, m), and the irradiance and moments again in
    DDGI's octahedral layout, <stem>_probes_irradiance_oct.exr and <stem>_probes_moments_oct.exr. Every bounce the
    settings ask for is in them; no camera is involved. Returns the summary (also in bake.json's form)."""
    from ..engine import probe_export
    from ..engine.passes.probe_project import IRRADIANCE_TEXELS

    settings = complete_settings(**settings)
    gi = settings["gi"]
    if gi.method != "probes":
        raise ConfigError(f"--target probes bakes the probe grid: use --method probes (got {gi.method})")
    # Every probe: an engine lights dynamic objects in the space no static surface's lookup reads.
    settings["probes"] = replace(settings["probes"], only_read_probes=False)
    out_dir = check_output_dir(Path(out_dir))
    stem = safe_name(Path(blend).stem)
    paths = {k: out_dir / f"{stem}_probes_{k}.exr" for k in probe_export.FILES}
    layout_path = out_dir / f"{stem}_probes.json"
    existing = [str(p) for p in (*paths.values(), layout_path) if p.exists()]
    if existing and not overwrite:
        raise SceneError(f"{existing[0]} exists (use --overwrite)")
    t0 = time.perf_counter()
    be, scene, method = _scene_without_camera(blend, settings, backend, _stderr_lines(progress),
                                              "capturing the scene, solving the probes")
    timings = method.solve_light_field()
    grid = method.grid
    light = be.read(method.light)
    if method.irradiance_encoding:
        irradiance = light[..., :3]
        coeffs = probe_export.sh_from_irradiance(grid, irradiance, IRRADIANCE_TEXELS)
        irradiance_oct = probe_export.octahedral_irradiance(grid, None, irradiance, IRRADIANCE_TEXELS)
    else:
        coeffs = probe_export.sh_grid(grid, light)
        irradiance = probe_export.irradiance_from_sh(grid, coeffs, IRRADIANCE_TEXELS)
        irradiance_oct = probe_export.octahedral_irradiance(grid, coeffs, None, IRRADIANCE_TEXELS)
    moments = be.read(method.moments)[..., :3].copy()
    moments[..., 2] = 0.0
    atlases = {"sh": probe_export.sh_table(grid, coeffs), "irradiance": irradiance, "moments": moments,
               "offsets": be.read(method.offset)[..., :3], "irradiance_oct": irradiance_oct,
               "moments_oct": probe_export.octahedral_moments(grid, moments)}
    for key, atlas in atlases.items():
        images.write_exr(paths[key], np.asarray(atlas, np.float32)[::-1])  # EXR row 0 = the atlas's top
    probes_off = np.flatnonzero(be.read(method.state)[..., 0].ravel() < 0.5)
    doc = probe_export.layout(grid, method.origin_m, method.probes_config.encoding, IRRADIANCE_TEXELS,
                              probes_off.tolist(), {k: p.name for k, p in paths.items()},
                              method.probes_config.relocate)
    layout_path.write_text(json.dumps(doc, indent=2))
    summary = {"blend": str(blend), "file": str(layout_path), "files": [str(p) for p in paths.values()],
               "dims": list(grid.dims), "spacing_m": grid.spacing_m, "probes_off": len(probes_off),
               "time_ms": round((time.perf_counter() - t0) * 1e3, 2),
               "config": {"probes": method.probes_config.to_dict(), "bounces": gi.bounces},
               "solves": method.solves, "solve_ms": round(timings["solve"], 2),
               "warnings": _volume_warnings(blend, scene)}
    print(f"{Path(blend).name}: probes {grid.dims[0]}x{grid.dims[1]}x{grid.dims[2]} -> {layout_path}")
    return summary


def _scene_without_camera(blend: Path, settings: dict, backend, say, doing: str):
    """Open `blend`, capture it without a camera (a volume depends on no view) and set it on a new
    method: (backend, scene, method)."""
    from .pipeline import backend as default_backend
    from .pipeline import open_blend

    say(f"bake: opening {blend}")
    open_blend(blend)
    define_light_switch()
    say(f"bake: {doing}")
    scene = replace(SceneCache().update(bpy.context.evaluated_depsgraph_get(), 1, 1), camera=None)
    be = backend or default_backend()
    method = methods.create(be, settings)
    method.set_scene(scene)
    return be, scene, method


def _volume_warnings(blend: Path, scene) -> list[str]:
    warnings = [w for w in [empty_light_warning(scene)] if w]
    for warning in warnings:
        print(f"warning: {Path(blend).name}: {warning}", file=sys.stderr)
    return warnings
