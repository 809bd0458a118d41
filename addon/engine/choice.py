"""Choosing a method and its settings for the scene at hand: scene features, an error and time model
fitted on the benchmark's results, and the choice for an error or a time budget.

Every benchmark row (a method at one of its registry settings, `registry.MethodSpec.bench`) has been
measured against Cycles on every benchmark scene. How wrong a row is on a new scene depends on the
scene: a method that leaks light through thin walls is worse in enclosed rooms, an L1 grid is worse
under a sun than under a spot, a gather of point VPLs is worse near glowing panels. The model says so
with a few numbers per scene (`FEATURES`, all computed from the engine's Scene, no Blender):

    log rel_rmse_8(row, scene) = a_row + b_method . x(scene)
    log ms(row, scene)         = c_row + d_method . (log10 triangles, log10 light faces)
                                 + log((1 - s_method) + s_method P / TIME_REFERENCE_PIXELS)

a_row, c_row: one intercept per row (how good and how fast the row is on the mean scene); b_method,
d_method: slopes shared by a method's rows (how the method's error and time move with the scene), fitted
by ridge least squares on standardised features, so a dozen scenes cannot make a slope explode. The last
term scales a time to the image's P pixels: s_method, the share of the method's update that grows with
the pixels at TIME_REFERENCE_PIXELS, is measured apart (tools/pixel_scaling.py), because the benchmark
times every row at one resolution and so cannot tell it. The model's own uncertainty is measured, not
assumed: `margin` is a quantile of its leave-one-scene-out error ratios, and a row counts as meeting a
budget E when its predicted error times the margin is at most E (tools/fit_choice.py fits, evaluates and
writes the model; benchmarks/choice/REPORT.md its figures).

Blender-free (numpy only); the bridge captures the scene and calls `scene_features` and `choose`.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import world
from .area_light import split_area_light
from .config import RsmConfig
from .errors import ConfigError
from .metrics import rel_noise_8, rel_rmse_8_against_noisy
from .passes.light_views import emissive_lights, views_for
from .scene import Scene

MODEL_PATH = Path(__file__).resolve().parent / "data" / "choice_model.json"

# The scene's description the model reads. Shares are of the light entering the scene's bounds (see
# light_shares); enclosure is the share of directions from points inside the bounds that meet geometry.
FEATURES = ("enclosure", "sun_share", "world_share", "shaped_share", "glossy_share", "log_triangles",
            "aspect", "bounces")
# Time goes with what every update rasterizes and gathers: triangles and light faces (each an RSM and,
# for most methods, a gather pass of its own); the pixels enter through the measured per-pixel shares
# (pixel_factor). Fitted as a slope, log10 pixels spanned only the aspects of the bench's 128 px images
# (3.91-4.21), and it extrapolated a lone 2:1 scene's times by 1000x and a 1920 x 1080 image's by 10^5.
TIME_FEATURES = ("log_triangles", "log_light_faces")
# The pixels at which the benchmark times its rows (a 128 px square) and the per-pixel shares are stated.
TIME_REFERENCE_PIXELS = 128 * 128
# A row's time may grow with the scene unlike its method's other rows (rsm's voxel visibility march costs
# per pixel and VPL, not per triangle as its RSM draws do: on Sibenik, 75k triangles, it took 2.7x rsm at
# 256 VPLs, on the Cornell box 7x), so each row's time slopes are its method's plus its own, the latter
# held to the method's by this ridge (the method slopes' is `ridge`, 1). Held out over the 15 benchmark
# scenes (tools/fit_choice.py --time-row-ridge R), the predicted time is within 2x of the measured on
# 66 % of rows with method slopes alone (rms of log measured / predicted 0.76), 74 % at row ridge 1 (0.68),
# 72 % at 20 (0.70), 68 % at 100 (0.74). `--verify`'s choice (met / within 2x of the fastest row meeting
# it at E = 0.1, 0.2, of 15 scenes) is 12 / 12, 12 / 11 with method slopes alone and at 50-300 (Sibenik:
# gather at 8 quads, 11.3 s, before rsm's voxel visibility, 5.4 s, predicted 12.1 s); 12 / 11, 12 / 12 at
# 1-10 (window-room at E = 0.1: rsm's voxel visibility, 0.75 s, before 64 VPLs, 0.16 s); 12 / 12, 12 / 12
# at 20-30. 20 is kept: chosen on the same scenes, so its figures flatter it a little.
TIME_ROW_RIDGE = 20.0

ENCLOSURE_DIRECTIONS = 64  # per point, a Fibonacci sphere
# The largest triangles alone decide whether a direction is closed (walls, floors, roofs), and a ray
# cast against a million of them costs seconds in numpy: the enclosure looks at this many, largest first.
ENCLOSURE_MAX_TRIANGLES = 20000
# Where the enclosure is looked at from: the bounds' centre and the eight points halfway from it to the
# corners (a camera may stand outside the geometry, as Cornell's does; a wall may hold the centre).
ENCLOSURE_POINTS = np.array([[0, 0, 0], *[[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]]) * 0.25
GLOSSY_ROUGHNESS = 0.5     # a lobe narrower than this shows as a reflection, not as diffuse light
GLOSSY_F0 = 0.1            # ... when it reflects at least this much (dielectrics reflect 0.04)


# -- features -------------------------------------------------------------------------------------------

def fibonacci_directions(n: int) -> np.ndarray:
    """(n, 3) unit vectors spread evenly over the sphere (the golden-angle spiral)."""
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    r = np.sqrt(np.maximum(1.0 - z * z, 0.0))
    phi = i * math.pi * (3.0 - math.sqrt(5.0))
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def rays_hit(origin: np.ndarray, directions: np.ndarray, triangles: np.ndarray, chunk: int = 4096) -> np.ndarray:
    """(n,) bool: does the ray from `origin` along each direction meet any triangle (Moller-Trumbore,
    both faces, t > 0)? Triangles are taken in chunks so a million of them stay within memory."""
    hit = np.zeros(len(directions), bool)
    d = directions[:, None, :]
    for start in range(0, len(triangles), chunk):
        tri = triangles[start:start + chunk].astype(np.float64)
        v0, e1, e2 = tri[:, 0], tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
        p = np.cross(d, e2[None])                       # (rays, tris, 3)
        det = np.einsum("rtk,tk->rt", p, e1)
        ok = np.abs(det) > 1e-12
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        s = origin[None, :] - v0                         # (tris, 3)
        u = np.einsum("rtk,tk->rt", p, s) * inv
        q = np.cross(s, e1)                              # (tris, 3)
        v = np.einsum("rk,tk->rt", directions, q) * inv
        t = np.einsum("tk,tk->t", e2, q)[None, :] * inv
        hit |= np.any(ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 1e-6), axis=1)
    return hit


def light_shares(scene: Scene) -> dict[str, float]:
    """Each kind's share of the power that enters the scene's bounds, in W (Cycles' units):
    lamps (point, spot, area) their power, a spot the share of the sphere its cone covers; a sun its
    irradiance over the bounds' area seen from it; the world pi L over the bounds' surface (a uniform
    radiance L gives irradiance pi L on every face); glowing triangles pi x radiance x area on both
    faces. Returns fractions of the total (all 0 when nothing emits)."""
    lo, hi = scene.bounds_m()
    size = np.maximum(hi - lo, 1e-6)
    faces = np.array([size[1] * size[2], size[0] * size[2], size[0] * size[1]])
    power = {"lamp": 0.0, "sun": 0.0, "world": 0.0, "shaped": 0.0}
    for light in scene.lights:
        if light.kind == "SUN":
            power["sun"] += light.sun_strength * float(np.mean(light.color)) * float(
                np.abs(np.asarray(light.direction, float)) @ faces)
        elif light.kind == "SPOT":
            cone = (1.0 - math.cos(min(light.spot_size_rad, 2 * math.pi) / 2.0)) / 2.0
            power["lamp"] += light.power_w * float(np.mean(light.color)) * cone
        elif light.kind == "AREA":
            power["shaped"] += light.power_w * float(np.mean(light.color))
        else:
            power["lamp"] += light.power_w * float(np.mean(light.color))
    world = scene.world_map if scene.world_map is not None else scene.world_color
    power["world"] = math.pi * float(np.mean(world)) * 2.0 * float(faces.sum())
    if scene.triangle_count:
        e1 = scene.positions_m[:, 1] - scene.positions_m[:, 0]
        e2 = scene.positions_m[:, 2] - scene.positions_m[:, 0]
        area = 0.5 * np.linalg.norm(np.cross(e1, e2), axis=1)
        power["shaped"] += 2.0 * math.pi * float(np.sum(np.mean(scene.emission, axis=1) * area))
    total = sum(power.values())
    return {k: (v / total if total > 0 else 0.0) for k, v in power.items()}


def light_faces(scene: Scene, rsm: RsmConfig) -> int:
    """How many light views (RSM faces) an update renders: the lamps (area lights in patches), the
    glowing meshes' lamps and the world's suns, as DirectMethod.light_views makes them."""
    lo, hi = scene.bounds_m()
    lights = []
    for light in scene.lights:
        lights += split_area_light(light, rsm.area_patches) if light.kind == "AREA" else [light]
    if scene.triangle_count:
        lights += emissive_lights(scene.positions_m, scene.emission, float((hi - lo).max()))
    world_map = scene.world_map
    if world_map is None and np.any(np.asarray(scene.world_color) > 0):
        world_map = world.constant_map(np.asarray(scene.world_color, np.float32))
    if world_map is not None and rsm.world_suns:
        lights += world.world_suns(world_map, rsm.world_suns)
    return sum(len(views_for(light, i, (lo, hi), rsm.resolution)) for i, light in enumerate(lights))


def scene_features(scene: Scene, bounces: int = 1, pixels: int = 128 * 128,
                   rsm: RsmConfig | None = None) -> dict[str, float]:
    """The numbers of FEATURES and TIME_FEATURES for `scene` (light faces at `rsm`, default settings
    when None)."""
    lo, hi = scene.bounds_m()
    size = np.maximum(hi - lo, 1e-9)
    n = scene.triangle_count
    enclosure = 0.0
    area = np.zeros(0)
    if n:
        e1 = scene.positions_m[:, 1] - scene.positions_m[:, 0]
        e2 = scene.positions_m[:, 2] - scene.positions_m[:, 0]
        area = 0.5 * np.linalg.norm(np.cross(e1, e2), axis=1)
        largest = scene.positions_m[np.argsort(area)[::-1][:ENCLOSURE_MAX_TRIANGLES]]
        dirs = fibonacci_directions(ENCLOSURE_DIRECTIONS)
        points = (lo + hi) / 2.0 + ENCLOSURE_POINTS * size
        enclosure = float(np.mean([rays_hit(p, dirs, largest) for p in points]))
    shares = light_shares(scene)
    glossy = 0.0
    if n:
        shiny = (scene.glossy_roughness() < GLOSSY_ROUGHNESS) & (scene.specular_f0().max(axis=1) >= GLOSSY_F0)
        glossy = float(area[shiny].sum() / max(area.sum(), 1e-30))
    return {"enclosure": enclosure, "sun_share": shares["sun"], "world_share": shares["world"],
            "shaped_share": shares["shaped"], "glossy_share": glossy, "log_triangles": math.log10(max(n, 1)),
            "aspect": float(size.min() / size.max()), "bounces": float(bounces),
            "log_pixels": math.log10(max(pixels, 1)),
            "log_light_faces": math.log10(max(light_faces(scene, rsm or RsmConfig()), 1))}


# -- the model ------------------------------------------------------------------------------------------

def row_key(method: str, setting: dict) -> str:
    """A row's name: the method and its settings, sorted ("lpv grid_cells=16 variant=improved")."""
    return " ".join([method, *(f"{k.split('.')[-1]}={setting[k]}" for k in sorted(setting))])


def _ridge(x: np.ndarray, y: np.ndarray, penalty: np.ndarray) -> np.ndarray:
    """argmin |x w - y|^2 + sum_j penalty_j w_j^2 (normal equations; columns of penalty 0 are free)."""
    a = x.T @ x + np.diag(penalty.astype(float))
    return np.linalg.lstsq(a, x.T @ y, rcond=None)[0]


@dataclass
class Model:
    """Fitted intercepts per row and slopes per method for error and time; feature scaling; margin."""

    rows: dict[str, dict]                       # key -> {"method", "setting", "a", "c"}
    slopes: dict[str, list[float]]              # method -> b (over FEATURES, standardised)
    time_slopes: dict[str, list[float]]         # row key -> d (over TIME_FEATURES, standardised)
    mean: dict[str, float]
    scale: dict[str, float]
    margin: float = 1.0                          # predicted error x margin <= budget counts as meeting it
    ridge: float = 1.0
    time_row_ridge: float = TIME_ROW_RIDGE
    scenes: dict[str, dict] = field(default_factory=dict)  # the features of the scenes fitted on
    per_pixel_share: dict[str, float] = field(default_factory=dict)  # method -> s (absent: 0)

    def _x(self, features: dict, names) -> np.ndarray:
        return np.array([(features[k] - self.mean[k]) / self.scale[k] for k in names])

    def pixel_factor(self, method: str, features: dict) -> float:
        """How much longer than at TIME_REFERENCE_PIXELS the method's update takes at the scene's pixels."""
        return pixel_factor(self.per_pixel_share.get(method, 0.0), features["log_pixels"])

    def predict(self, key: str, features: dict) -> tuple[float, float]:
        """(rel_rmse_8, ms) the model expects of row `key` on a scene with these features."""
        row = self.rows[key]
        err = row["a"] + float(np.dot(self.slopes[row["method"]], self._x(features, FEATURES)))
        ms = row["c"] + float(np.dot(self.time_slopes[key], self._x(features, TIME_FEATURES)))
        return math.exp(err), math.exp(ms) * self.pixel_factor(row["method"], features)

    def to_json(self) -> dict:
        return {"rows": self.rows, "slopes": self.slopes, "time_slopes": self.time_slopes, "mean": self.mean,
                "scale": self.scale, "margin": self.margin, "ridge": self.ridge,
                "time_row_ridge": self.time_row_ridge, "scenes": self.scenes,
                "per_pixel_share": self.per_pixel_share, "features": list(FEATURES),
                "time_features": list(TIME_FEATURES)}

    @classmethod
    def from_json(cls, data: dict) -> Model:
        if data.get("features") != list(FEATURES) or data.get("time_features") != list(TIME_FEATURES):
            raise ConfigError("the choice model was fitted on other features: re-run tools/fit_choice.py")
        return cls(rows=data["rows"], slopes=data["slopes"], time_slopes=data["time_slopes"], mean=data["mean"],
                   scale=data["scale"], margin=data["margin"], ridge=data["ridge"],
                   time_row_ridge=data["time_row_ridge"], scenes=data["scenes"],
                   per_pixel_share=data["per_pixel_share"])


def pixel_factor(per_pixel_share: float, log_pixels: float) -> float:
    """t(P) / t(TIME_REFERENCE_PIXELS) for an update whose share `per_pixel_share` at the reference grows
    with the pixels and the rest does not: (1 - s) + s P / P_ref, P = 10^log_pixels."""
    return (1.0 - per_pixel_share) + per_pixel_share * 10.0 ** log_pixels / TIME_REFERENCE_PIXELS


def load(path: Path = MODEL_PATH) -> Model:
    if not path.is_file():
        raise ConfigError(f"no choice model at {path}: run tools/fit_choice.py")
    return Model.from_json(json.loads(path.read_text()))


def fit(records: list[dict], features: dict[str, dict], ridge: float = 1.0,
        per_pixel_share: dict[str, float] | None = None, time_row_ridge: float = TIME_ROW_RIDGE) -> Model:
    """Fit on benchmark records ({"scene", "method", "setting", "rel_rmse_8", "total_ms"}; rows without
    an error are skipped) and the features of their scenes; each record's time is taken back to
    TIME_REFERENCE_PIXELS by its method's `per_pixel_share` (absent: 0, a time that ignores the pixels);
    each row's time slopes depart from its method's under `time_row_ridge`. Margin 1 (set by the
    evaluation)."""
    recs = [r for r in records if r.get("rel_rmse_8") and r["scene"] in features and r.get("total_ms")]
    if not recs:
        raise ConfigError("no benchmark records with errors to fit on")
    names = sorted({k for k in (*FEATURES, *TIME_FEATURES)})
    table = np.array([[features[s][k] for k in names] for s in sorted(features)])
    mean = {k: float(table[:, i].mean()) for i, k in enumerate(names)}
    scale = {k: float(table[:, i].std()) or 1.0 for i, k in enumerate(names)}
    keys = sorted({row_key(r["method"], r["setting"]) for r in recs})
    methods = sorted({r["method"] for r in recs})
    model = Model(rows={}, slopes={}, time_slopes={}, mean=mean, scale=scale, ridge=ridge,
                  time_row_ridge=time_row_ridge,
                  scenes={s: features[s] for s in sorted({r["scene"] for r in recs})},
                  per_pixel_share=dict(per_pixel_share or {}))

    def solve(names_used, target, row_ridge=None):
        """(intercept per row, slopes per method); with row_ridge, also each row's own departure from its
        method's slopes, penalised by row_ridge, and the slopes per row (its method's plus its own)."""
        nk, nf, nm = len(keys), len(names_used), len(methods)
        x = np.zeros((len(recs), nk + (nm + (nk if row_ridge is not None else 0)) * nf))
        for i, r in enumerate(recs):
            k, m = keys.index(row_key(r["method"], r["setting"])), methods.index(r["method"])
            x[i, k] = 1.0
            x[i, nk + m * nf: nk + (m + 1) * nf] = model._x(features[r["scene"]], names_used)
            if row_ridge is not None:
                x[i, nk + (nm + k) * nf: nk + (nm + k + 1) * nf] = model._x(features[r["scene"]], names_used)
        y = np.array([math.log(target(r)) for r in recs])
        penalty = np.r_[np.zeros(nk), np.full(nm * nf, ridge), np.full(x.shape[1] - nk - nm * nf, row_ridge or 0.0)]
        w = _ridge(x, y, penalty)
        per_method = {m: w[nk + i * nf: nk + (i + 1) * nf] for i, m in enumerate(methods)}
        if row_ridge is None:
            return w[:nk], {m: v.tolist() for m, v in per_method.items()}
        method_of = {row_key(r["method"], r["setting"]): r["method"] for r in recs}
        return w[:nk], {k: (per_method[method_of[k]] + w[nk + (nm + j) * nf: nk + (nm + j + 1) * nf]).tolist()
                        for j, k in enumerate(keys)}

    a, model.slopes = solve(FEATURES, lambda r: r["rel_rmse_8"])
    c, model.time_slopes = solve(TIME_FEATURES, lambda r: r["total_ms"] / model.pixel_factor(r["method"],
                                                                                        features[r["scene"]]),
                                 row_ridge=time_row_ridge)
    for i, key in enumerate(keys):
        r = next(r for r in recs if row_key(r["method"], r["setting"]) == key)
        model.rows[key] = {"method": r["method"], "setting": r["setting"], "a": float(a[i]), "c": float(c[i])}
    return model


# -- the choice -----------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Choice:
    key: str
    method: str
    setting: dict
    predicted_rel_rmse_8: float   # the model's expectation
    predicted_ms: float
    meets_budget: bool
    why: str


def choose(model: Model, features: dict, error_budget: float | None = None,
           time_budget_ms: float | None = None, methods: tuple[str, ...] | None = None) -> Choice:
    """The fastest row whose predicted error x margin is within `error_budget`, or the least error
    among the rows predicted within `time_budget_ms` (exactly one budget). When no row meets it: the
    row closest to it (least error, or least time), with meets_budget False and why saying so.
    One margin for every method: per-method margins (each method's own 80 % quantile of measured /
    predicted, held out) met E = 0.3 on 12 scenes, not 14, and were within 2x of the fastest row on 1,
    not 5, against one 80 % margin (rsm's own, x1.91, was above the common x1.55)."""
    if (error_budget is None) == (time_budget_ms is None):
        raise ConfigError("give exactly one of an error budget and a time budget")
    preds = [(k, *model.predict(k, features)) for k, row in model.rows.items()
             if methods is None or row["method"] in methods]
    if not preds:
        raise ConfigError("the choice model has no row of the methods allowed")
    if error_budget is not None:
        ok = [p for p in preds if p[1] * model.margin <= error_budget]
        if ok:
            k, err, ms = min(ok, key=lambda p: p[2])
            why = (f"fastest of {len(ok)} settings expected within rel_rmse_8 {error_budget:g} "
                   f"(x{model.margin:.2f} margin): {err:.3f}, ~{ms:.0f} ms")
        else:
            k, err, ms = min(preds, key=lambda p: p[1])
            why = f"no setting is expected within rel_rmse_8 {error_budget:g}: the most accurate, {err:.3f}"
        met = bool(ok)
    else:
        ok = [p for p in preds if p[2] <= time_budget_ms]
        if ok:
            k, err, ms = min(ok, key=lambda p: p[1])
            why = f"least expected error of {len(ok)} settings within {time_budget_ms:g} ms: {err:.3f}, ~{ms:.0f} ms"
        else:
            k, err, ms = min(preds, key=lambda p: p[2])
            why = f"no setting is expected within {time_budget_ms:g} ms: the fastest, ~{ms:.0f} ms"
        met = bool(ok)
    row = model.rows[k]
    return Choice(k, row["method"], dict(row["setting"]), err, ms, met, why)


# -- verifying it against the scene ---------------------------------------------------------------------

# `render --method auto --error-budget E --verify`: the model's choice misses the budget where a scene
# is unlike the benchmark's (the only sun scene, the only thin wall), while the path-traced check (below)
# puts every benchmark row's estimate within a factor 1.5 of its measured error (benchmarks/choice/
# REPORT.md). So the candidates come in stages: the rows predicted within VERIFY_STAGES[0] budgets
# (x margin), fastest first by their predicted time; only when none of them is accepted, the further rows
# predicted within the next stage's budgets, and so on. The first whose estimate is within VERIFY_ACCEPT
# budgets is taken; then up to VERIFY_FASTER rows predicted faster than VERIFY_FASTER_SHARE of its time
# are tried whatever their predicted error (cheap beside it), and the first within replaces it; at most
# VERIFY_MAX_TRIES are rendered in all. One stage reaching 3 budgets: with an estimate this close the
# search can afford rows the model expects well above the budget, and tried fastest first they cost
# little. Swept on the benchmark's 15 held-out scenes (`tools/fit_choice.py RESULTS --cache C
# --sweep-verify`; chosen on those same scenes, so its figures flatter it a little; the model's margin
# at tools/fit_choice.py's MARGIN_QUANTILE, 0.7). Met / within 2x of the fastest row meeting it / mean
# rows rendered, at E = 0.1, 0.2, 0.3 (of 15 scenes; at E = 0.1 only 12 have a row within the budget),
# the estimate within 1.5x on 15, 15, 15 at each:
# - stage (3), at most 40, accept 1, 2 faster: 12 / 12 / 9.7, 12 / 12 / 9.7, 15 / 15 / 4.9;
# - no faster rows: 12 / 11, 12 / 12, 15 / 15 (window-room's fastest row within 0.1, rsm at 64 VPLs,
#   is one the model expects 6x worse than it is, beyond 3 budgets);
# - accept 0.95 (a margin for the estimate's spread of a few per cent): 12 / 11, 14 / 13, 15 / 15: at
#   E = 0.2 the two rows it refuses and accept 1 takes measure 0.200 and 0.202 against references whose
#   own noise is ~0.02, and at E = 0.1 it refuses cornell's fastest row (measured 0.0996, estimated
#   0.098) for one 4.8x slower;
# - stage (2.5), at most 16: 12 / 12, 11 / 11, 15 / 15; stages (1, 2), at most 4, no faster rows:
#   12 / 5, 13 / 10, 15 / 13 after about two rows: the fastest row within the budget is often one the
#   model expects above it;
# - at most 16 rows at stage (3): 12 / 12, 10 / 10, 15 / 15.
# With the check as noisy as half the error it resolves (CHECK_NOISE 0.5, a quarter of the Cycles
# samples), stage (3) at most 40 without faster rows gave 12 / 10, 12 / 12, 15 / 15 at accept 1.
VERIFY_STAGES = (3.0,)
VERIFY_MAX_TRIES = 40
VERIFY_ACCEPT = 1.0
VERIFY_FASTER = 2
VERIFY_FASTER_SHARE = 0.5


def verify(model: Model, features: dict, error_budget: float, estimate,
           methods: tuple[str, ...] | None = None) -> tuple[str | None, list[dict]]:
    """(the row taken: the first candidate whose run-time estimate is within VERIFY_ACCEPT x `error_budget`,
    or a faster one found after it; None when none is; every row tried with its estimate). The
    candidates: per stage of VERIFY_STAGES, the rows predicted within that many budgets and not yet
    considered, fastest first. Once one is taken, up to VERIFY_FASTER rows not yet tried and predicted
    faster than VERIFY_FASTER_SHARE of its time, whatever their predicted error, fastest first: the first
    of them within the budget replaces it. `estimate(key)` gives a row's run-time estimate (its image
    judged by the path-traced check), or None where it has none (the row is then skipped, not counted).
    At most VERIFY_MAX_TRIES rows are tried in all."""
    preds = {k: model.predict(k, features) for k, row in model.rows.items()
             if methods is None or row["method"] in methods}
    tried: list[dict] = []
    considered: set[str] = set()

    def first_within(keys) -> str | None:
        for key in keys:
            if len(tried) == VERIFY_MAX_TRIES:
                return None
            considered.add(key)
            found = estimate(key)
            if found is None:
                continue
            tried.append({"row": key, "estimated_rel_rmse_8": float(found)})
            if found <= VERIFY_ACCEPT * error_budget:
                return key
        return None

    def fastest_first(keys) -> list[str]:
        return sorted(keys, key=lambda k: preds[k][1])

    for loosening in VERIFY_STAGES:
        taken = first_within(fastest_first(k for k, (err, _) in preds.items() if k not in considered
                                           and err * model.margin <= loosening * error_budget))
        if taken is not None:
            faster = fastest_first(k for k, (_, ms) in preds.items() if k not in considered
                                   and ms < VERIFY_FASTER_SHARE * preds[taken][1])
            return first_within(faster[:VERIFY_FASTER]) or taken, tried
        if len(tried) == VERIFY_MAX_TRIES:
            break
    return None, tried


def take_verified(model: Model, features: dict, requested: dict, settings: dict, decided: dict,
                  error_budget: float, accepted: str | None, tried: list[dict],
                  extra: dict | None = None) -> tuple[dict, dict]:
    """What runs after `verify` (camera or bake): the row accepted, else the one tried whose estimate is
    least (least_estimated), else the model's choice (`settings`, nothing could be tried). Returns the
    settings to run (`requested`, the user's, with that row's setting) and `decided` (decide's) with
    choice["verified"] = the rows tried, the one accepted and `extra` (the check's figures), and the
    estimate the row's path-traced one."""
    decided["choice"]["verified"] = {"tried": tried, "accepted": accepted, **(extra or {})}
    key = accepted if accepted is not None else least_estimated(tried)
    if key is None:
        return settings, decided
    found = next(t["estimated_rel_rmse_8"] for t in tried if t["row"] == key)
    # The run-time estimate, not the model's: it is the better judge on held-out scenes (REPORT.md).
    decided.update(estimated_rel_rmse_8=found, estimate_row=key, estimate_source="path-traced check")
    if accepted is not None and key == decided["choice"]["row"]:
        return settings, decided
    row = model.rows[key]
    predicted, predicted_ms = model.predict(key, features)
    why = (f"fastest of the settings tried whose path-traced check is within rel_rmse_8 {error_budget:g}: "
           f"{found:.3f}" if accepted is not None else
           f"no setting tried came within rel_rmse_8 {error_budget:g} by the path-traced check; this one came "
           f"nearest: {found:.3f}")
    decided["choice"].update(method=row["method"], setting=row["setting"], row=key, predicted_rel_rmse_8=predicted,
                             predicted_ms=predicted_ms, meets_budget=accepted is not None, why=why)
    return apply_row(requested, row["method"], row["setting"]), decided


def least_estimated(tried: list[dict]) -> str | None:
    """Of the rows `verify` tried (none within the budget), the one whose run-time estimate is least:
    what runs then, rather than the model's unchecked choice: the estimate is the better judge of the two
    (every benchmark row's within a factor 1.5 of its measured error, the model's on 58 %;
    benchmarks/choice/REPORT.md), so this is the most accurate row tried."""
    return min(tried, key=lambda t: t["estimated_rel_rmse_8"])["row"] if tried else None


# -- applying it ----------------------------------------------------------------------------------------

AUTO = "auto"  # the command line's and the panel's name for "choose the method for a budget"


def apply_row(settings: dict, method: str, setting: dict) -> dict:
    """{group: config} with gi.method = method and each "group.field" of the row's setting replaced
    (the other fields, the image's size, seed and bounces, stay the caller's)."""
    from dataclasses import replace

    out = dict(settings)
    out["gi"] = replace(out["gi"], method=method)
    for key, value in setting.items():
        group, name = key.split(".")
        out[group] = replace(out[group], **{name: value})
    return out


def row_for(model: Model, settings: dict) -> str | None:
    """The model's row that `settings` are (the method's defaults with the row's setting, judged on the
    groups the method reads), or None: the model knows no such setting."""
    from . import registry
    from .config import settings as complete

    method = settings["gi"].method
    groups = {r.split(".")[0] for r in registry.get(method).reads}
    for key, row in model.rows.items():
        if row["method"] != method:
            continue
        candidate = apply_row(complete(gi=settings["gi"]), method, row["setting"])
        if all(candidate[g] == settings[g] for g in groups):
            return key
    return None


def decide(scene: Scene, settings: dict, pixels: int, error_budget: float | None = None,
           time_budget_ms: float | None = None, model: Model | None = None) -> tuple[dict, dict]:
    """The settings to run and what stats.json / bake.json say of them: with a budget, the choice
    (settings replaced by its row) and why; always the model's estimate of the error where it knows
    the setting (`estimated_rel_rmse_8`, None where it does not, with the reason)."""
    budget = error_budget is not None or time_budget_ms is not None
    if model is None:
        try:
            model = load()
        except ConfigError as exc:
            if budget:
                raise
            return settings, {"estimated_rel_rmse_8": None, "estimate_note": str(exc)}
    feats = scene_features(scene, settings["gi"].bounces, pixels, settings["rsm"])
    info: dict = {"features": feats}
    if budget:
        from . import registry

        able = registry.computing(settings["gi"].bounces)
        c = choose(model, feats, error_budget, time_budget_ms, methods=able)
        settings = apply_row(settings, c.method, c.setting)
        info["choice"] = {"method": c.method, "setting": c.setting, "row": c.key,
                          "predicted_rel_rmse_8": c.predicted_rel_rmse_8, "predicted_ms": c.predicted_ms,
                          "meets_budget": c.meets_budget, "why": c.why,
                          "budget": {"rel_rmse_8": error_budget} if error_budget is not None
                          else {"ms": time_budget_ms}}
    key = row_for(model, settings)
    if key is None:
        info.update(estimated_rel_rmse_8=None,
                    estimate_note="the choice model has no benchmark row with these settings")
    else:
        info.update(estimated_rel_rmse_8=model.predict(key, feats)[0], estimate_row=key, estimate_source="model")
    return settings, info


# -- the run-time check ---------------------------------------------------------------------------------

# The path-traced check (`render --verify`, `--self-check`): a row's error estimated against Cycles on
# the scene itself. Two Cycles renders of the Diffuse Indirect pass with other seeds; their mean's noise,
# measured from their spread, is subtracted from the row's squared difference to it
# (metrics.rel_rmse_8_against_noisy), so the check needs only as many samples as make that difference
# precise: CHECK_NOISE x the error to resolve. A pilot pair at CHECK_PILOT_SPP measures the scene's noise;
# Monte Carlo noise falls as 1 / sqrt(spp), which gives the pair's spp (check_spp). At 0.25 every
# benchmark row's estimate was within a factor 1.5 of its measured error, and --verify (at accept
# 0.95) met the budget on 14 held-out scenes at E = 0.2 against 13 at 0.5, for 4x the samples: at 128 px
# the pair took 1.0-84 s at E = 0.1 on the 2-core machine (window-sky's sky at 1731 spp), 0.3-23 s at E = 0.2.
CHECK_PILOT_SPP = 4
CHECK_NOISE = 0.25
CHECK_MAX_SPP = 4096
# A self-check resolves the error its pilot pair finds, but no finer than this (a nearly exact image would
# otherwise ask for CHECK_MAX_SPP): the direct light's errors against Cycles are ~0.01 (docs/DIRECT.md).
CHECK_MIN_RESOLVE = 0.01
# Seeds of the pilot pair and the check pair: far from 0 and 1, a benchmark reference's (Cycles draws the
# first n samples of a seed alike at any spp, so a check with the reference's seed would share them).
CHECK_SEEDS = ((7001, 7002), (7003, 7004))


def check_spp(pilot_noise: float, target_noise: float) -> int:
    """Samples per render of the check pair whose mean has relative noise `target_noise`, from the pilot
    pair's mean's (`pilot_noise`, two renders at CHECK_PILOT_SPP): (pilot / target)^2 x CHECK_PILOT_SPP,
    within [CHECK_PILOT_SPP, CHECK_MAX_SPP]."""
    if not target_noise > 0:
        raise ConfigError(f"the check's noise must be > 0, got {target_noise}")
    n = CHECK_PILOT_SPP * (pilot_noise / target_noise) ** 2
    return int(min(CHECK_MAX_SPP, max(CHECK_PILOT_SPP, math.ceil(n))))


def path_traced_check(resolve: float | None, render, progress=lambda step: None,
                      ours: np.ndarray | None = None) -> dict | None:
    """The check pair of the path-traced check, precise enough to resolve an error of `resolve`
    (rel_rmse_8): a pilot pair at CHECK_PILOT_SPP measures the scene's noise, then a pair at check_spp for
    a mean as noisy as CHECK_NOISE x `resolve`. `resolve` None: the error of `ours` (RGBA, the image the
    check will judge) as the pilot pair estimates it, at least CHECK_MIN_RESOLVE (a self-check resolves
    the error it finds). `render(spp, seed)` -> (the path tracer's light, (h, w, 3);
    the texels or pixels it covers, (h, w) bool; its time in s): a camera image or a lightmap
    (bridge/pipeline.camera_check_render, bridge/bake.bake_check_render). Returns {"images": the pair,
    "mask": what the pair's first render covers, "spp", "pilot_noise", "noise": the pair's mean's
    rel_noise_8, "time_s": all four renders}; None where nothing is covered."""
    def pair(spp: int, seeds) -> tuple[list, np.ndarray, float]:
        progress(f"path-traced check: {spp} spp, seeds {seeds[0]} and {seeds[1]}")
        rendered = [render(spp, seed) for seed in seeds]
        return [r[0] for r in rendered], rendered[0][1], sum(r[2] for r in rendered)

    pilot, mask, pilot_s = pair(CHECK_PILOT_SPP, CHECK_SEEDS[0])
    pilot_noise = rel_noise_8(pilot, mask)
    if pilot_noise is None:
        return None
    if resolve is None:
        found = rel_rmse_8_against_noisy(ours[..., :3], pilot, mask & (ours[..., 3] > 0.5))
        resolve = max(found or 0.0, CHECK_MIN_RESOLVE)
    spp = check_spp(pilot_noise, CHECK_NOISE * resolve)
    checks, mask, check_s = pair(spp, CHECK_SEEDS[1])
    return {"images": checks, "mask": mask, "spp": spp, "pilot_noise": pilot_noise,
            "noise": rel_noise_8(checks, mask), "time_s": pilot_s + check_s}


def path_traced_estimate(ours: np.ndarray, check: dict) -> float | None:
    """`ours` (RGBA: light, alpha = what it covers) judged by a path_traced_check: its estimated rel_rmse_8
    against the converged path tracer, over what both cover; None where nothing is."""
    return rel_rmse_8_against_noisy(ours[..., :3], check["images"], check["mask"] & (ours[..., 3] > 0.5))


def check_stats(check: dict) -> dict:
    """What stats.json and bake.json say of a path_traced_check: its samples, its mean's noise, its time."""
    return {"check_spp": check["spp"], "check_noise": check["noise"], "check_time_s": check["time_s"]}
