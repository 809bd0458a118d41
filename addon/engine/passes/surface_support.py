"""Surface support: how much of the denoise filter's kernel lies on each pixel's own surface.

Input: the G-buffer's position and normal. Output: `support` (R32F, the G-buffer's size): the B3-weighted
mean of the G-buffer weights of the 24 neighbours STEP_PX apart (common/gbuffer_weight.glsl's
surface_support, the filter's own weights at its second iteration's spacing), 1 on a flat plane facing
the camera, -1 for a pixel without a covered neighbour, 1 where there is no geometry.

Why: the denoise filter averages a pixel with its surface's neighbours. A pixel with few of them (a thin
column, a leaf, the last pixel before a crease) keeps its own gather's noise, and on Sponza such pixels
(support below THRESHOLD, 9-12 % of them) hold 72 % of the squared noise between two seeds. The
stochastic gathers draw more samples there: vct's cones (VctConfig.support_gathers) and rsm's VPLs
(RsmConfig.support_draws, in every one of its per-face dispatches). DirectMethod.measure_support runs it
once per update.

The same holds for a whole image that is small: the filter's reach is a fixed share of the image, so it
averages few pixels. `image_samples` says how often every pixel samples there (GIConfig.sample_budget_px);
a pixel of low support samples support_gathers / support_draws times that.
"""

from __future__ import annotations

from ..backends.base import Backend, Image, Sampler, ShaderSpec, Var, group_count
from .declare import GBUF_NORMAL, GBUF_POSITION, PassDecl, Port
from .denoise import Params, weight_uniforms

STEP_PX = 2  # the filter's second iteration's tap spacing
# Every pixel samples at most this often per update: the noise falls as 1 / sqrt(samples), the time grows
# with them, and a smaller image is better served by progressive refinement.
MAX_IMAGE_SAMPLES = 4
THRESHOLD = 0.3  # below it a pixel draws more samples

SPEC = ShaderSpec(
    name="surface_support",
    compute="common/surface_support.comp.glsl",
    local_size=(8, 8, 1),
    samplers=(Sampler("gbuf_position", "2D"), Sampler("gbuf_normal", "2D")),
    images=(Image("support", "2D", "R32F", "write"),),
    uniforms=(Var("normal_power", "float"), Var("plane_sigma", "float"), Var("position_sigma", "float")),
    defines=(("STEP_PX", str(STEP_PX)),),
)

SUPPORT = Port("gbuffer", "support", "R32F", "image",
               "the share of the denoise kernel on the pixel's own surface (1: a flat plane)")
DECL = PassDecl("surface_support", "gather", (GBUF_POSITION, GBUF_NORMAL), (SUPPORT,),
                "how much of its surface the denoise filter finds around each pixel")


def image_samples(size: tuple[int, int], budget_px: int) -> int:
    """How many times every pixel of an image of `size` samples (vct's gathers, rsm's sets of VPL
    draws): budget_px // pixels, at least 1 and at most MAX_IMAGE_SAMPLES (budget_px 0: once;
    GIConfig.sample_budget_px). The denoise filter's reach is a fixed share of the image
    (denoise.iterations_for), so what it averages holds pixels x samples draws: an image of a quarter
    of the pixels sampled four times leaves the noise of the larger one, for the larger one's time."""
    pixels = size[0] * size[1]
    return max(1, min(MAX_IMAGE_SAMPLES, budget_px // max(1, pixels)))


def run(backend: Backend, gbuf: dict, support) -> None:
    """Write `support` (R32F, the G-buffer's size) from the G-buffer's position and normal."""
    backend.dispatch(backend.program(SPEC), group_count(support.size, SPEC.local_size),
                     uniforms=weight_uniforms(Params()),
                     samplers={"gbuf_position": gbuf["position"], "gbuf_normal": gbuf["normal"]},
                     images={"support": support})
