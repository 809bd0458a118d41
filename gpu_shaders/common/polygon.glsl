// Irradiance from polygonal emitters (area lights with their shape, emissive triangles): the GLSL twin
// of addon/engine/area_light.py. The emitter table `emitters` (RGBA32F) holds one polygon per row:
// texels 0..3 its vertices (xyz, m; texel 0's w = the vertex count, 3 or 4), texel 4 its radiance (rgb,
// W/m^2/sr) and sidedness (+1 emits towards (v1 - v0) x (v2 - v0), -1 away from it, 0 both ways).

const int POLYGON_MAX_VERTICES = 4;

// E / L (sr) at p with unit normal n from the polygon v[0..count), the part above p's horizon (clipped
// by Sutherland-Hodgman), whichever way it winds: Lambert's formula, (1/2) |sum theta_i n.g_i|.
// A convex polygon clipped by one plane gains at most one corner; corners that fp32 rounding adds
// beyond that (signs alternating along a polygon nearly in the horizon plane) are dropped rather than
// written past the array, which is undefined.
float polygon_irradiance(vec3 p, vec3 n, vec3 v[POLYGON_MAX_VERTICES], int count) {
    const int CLIPPED_MAX = POLYGON_MAX_VERTICES + 1;
    vec3 c[CLIPPED_MAX];
    int m = 0;
    for (int i = 0; i < count; ++i) {
        vec3 a = v[i] - p;
        vec3 b = v[(i + 1) % count] - p;
        float da = dot(n, a);
        float db = dot(n, b);
        if (da > 0.0 && m < CLIPPED_MAX) {
            c[m] = a;
            m += 1;
        }
        if ((da > 0.0) != (db > 0.0) && m < CLIPPED_MAX) {
            c[m] = a + (b - a) * (da / (da - db));
            m += 1;
        }
    }
    if (m < 3) {
        return 0.0;
    }
    float total = 0.0;
    for (int i = 0; i < m; ++i) {
        vec3 a = normalize(c[i]);
        vec3 b = normalize(c[(i + 1) % m]);
        vec3 axb = cross(a, b);
        float len = length(axb);
        if (len > 1e-20) {
            // atan rather than acos: exact for the tiny angles of a small, far polygon in fp32
            total += atan(len, dot(a, b)) * dot(n, axb) / len;
        }
    }
    return 0.5 * abs(total);
}

// How far from a polygon's plane, as a share of the coordinates' magnitude, a receiver counts as lying on
// it. The emitting surface's own G-buffer pixels lie a few fp32 ulps (1e-7 of the coordinates) to
// either side of the plane; just off it the polygon fills the receiver's hemisphere (E = pi L), on it the
// polygon is seen edge-on (E = 0), and Cycles' Diffuse Direct of a glowing surface holds no light from
// itself. 1e-5 is ~100 ulps, and 0.1 mm in a 10 m scene: no real receiver lies nearer.
const float ON_PLANE_SHARE = 1e-5;

// Sum over rows [first, first + count) of the table: radiance x E / L, per colour (W/m^2), the rows
// whose emitting side p does not face, or whose plane p lies on, left out.
vec3 emitter_irradiance(sampler2D emitters, int first, int count, vec3 p, vec3 n) {
    vec3 e = vec3(0.0);
    for (int r = first; r < first + count; ++r) {
        vec3 v[POLYGON_MAX_VERTICES];
        vec4 t0 = texelFetch(emitters, ivec2(0, r), 0);
        int k = int(t0.w + 0.5);
        v[0] = t0.xyz;
        for (int i = 1; i < POLYGON_MAX_VERTICES; ++i) {
            v[i] = texelFetch(emitters, ivec2(i, r), 0).xyz;
        }
        vec4 rad = texelFetch(emitters, ivec2(POLYGON_MAX_VERTICES, r), 0);
        vec3 face = cross(v[1] - v[0], v[2] - v[0]);
        float side = dot(face, p - v[0]);
        if (rad.w * side < 0.0) {
            continue;  // p is behind this polygon's emitting side
        }
        if (abs(side) <= ON_PLANE_SHARE * max(length(p), length(v[0])) * length(face)) {
            continue;  // p lies on the polygon's plane: the emitter itself, or a surface flush with it
        }
        e += rad.rgb * polygon_irradiance(p, n, v, k);
    }
    return e;
}
