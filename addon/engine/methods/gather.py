"""Method `gather`: distance-corrected final gathering from the probes' cube maps (Umenhoffer &
Szirmay-Kalos, "Robust diffuse final gathering on the GPU", seeds 001). docs/GATHER.md.

The probes' grid is the paper's set of reference points: setup is the probes' (their atlas G-buffer of
every probe's six faces, the distance moments), and so is the solve's shading (the sky pass and the
direct pass per light face on the atlas). The solve then turns every probe face into M x M quad lights (gather_texels,
gather_quads: GatherConfig.face_quads), and the gather sums, at every pixel or lightmap texel, each
quad's radiance times its form factor there, over the probes around it weighted as `probes` weighs
them (gather_form_factor). Bounces 2..N: the probes' own bounces (their SH field, docs/PROBES.md)
light the atlas, so the quads of bounce N carry bounces 1..N-1 and `gather` does the last one.
Products: direct, indirect (Cycles' Diffuse Indirect), albedo.
"""

from __future__ import annotations

from .. import registry
from ..config import GatherConfig, ProbesConfig
from ..errors import ConfigError
from ..passes import declare, gather_form_factor, gather_quads
from .direct import OneBounceMethod
from .probes import ProbesMethod


class GatherMethod(ProbesMethod):
    spec = registry.get("gather")
    # The probes' setup and solve (their bounces' passes run only with GIConfig.bounces > 1), the quads,
    # and in the gather the form factors instead of the probes' lookup.
    PASSES = declare.extend({**ProbesMethod.PASSES, "gather": OneBounceMethod.PASSES["gather"]},
                            solve=(gather_quads.TEXELS_DECL, gather_quads.QUADS_DECL),
                            gather=(gather_form_factor.DECL,))

    def __init__(self, backend, gi, rsm_config, gather_config: GatherConfig | None = None,
                 probes_config: ProbesConfig | None = None):
        super().__init__(backend, gi, rsm_config, probes_config)
        self.gather_config = gather_config if gather_config is not None else GatherConfig()
        m, n = self.gather_config.face_quads, self.probes_config.face_texels
        if n % m:
            # A quad's corners are texel corners, where the texels' planes say how far the surface is.
            raise ConfigError(f"GatherConfig.face_quads = {m} must divide ProbesConfig.face_texels = {n}")

    def set_scene(self, scene) -> None:
        super().set_scene(scene)
        self.quads = gather_quads.allocate(self.backend, self.grid, self.gather_config.face_quads)

    def finish_solve(self, timings: dict[str, float]) -> None:
        self.finish_direct()
        be, grid = self.backend, self.grid
        indirect = None
        if self.gi.bounces > 1:
            # The probes' field with bounces 1..N-1, read back at the atlas: what the last bounce re-emits.
            self.encode_bounces(timings, self.gi.bounces - 1)
            self.read_back(timings)
            indirect = self.atlas_indirect
        with self.step(timings, gather_quads.TEXELS_DECL):
            gather_quads.texels(be, self.atlas, self.atlas_direct, self.quads, grid, self.offset, indirect)
        with self.step(timings, gather_quads.QUADS_DECL):
            gather_quads.quads(be, self.quads, grid, self.gather_config.face_quads)

    def gather_pixels(self, timings: dict[str, float]) -> None:
        with self.step(timings, gather_form_factor.DECL):
            gather_form_factor.run(self.backend, self.gbuf["position"], self.gbuf["normal"], self.quads,
                                   self.moments, self.state, self.offset, self.indirect, self.grid, self.probes_config,
                                   self.gather_config)
