// Evaluates the functions of common/sh.glsl for one direction per texel, so tests can compare
// them with addon/engine/sh.py: basis -> basis_out, cosine lobe -> lobe_out,
// (irradiance of the coefficients in coeffs about the direction, evaluate) -> scalar_out.xy.
#include "common/sh.glsl"

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, textureSize(dirs, 0)))) {
        return;
    }
    vec3 d = texelFetch(dirs, p, 0).xyz;
    vec4 c = texelFetch(coeffs, p, 0);
    imageStore(basis_out, p, sh_basis(d));
    imageStore(lobe_out, p, sh_cosine_lobe(d));
    imageStore(scalar_out, p, vec4(sh_irradiance(c, d), sh_evaluate(c, d), 0.0, 0.0));
}
