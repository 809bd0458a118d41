// The probe grid and its atlas (addon/engine/probe_grid.py is the numpy twin; docs/PROBES.md).
// Uniforms: probe_first (m, probe (0,0,0)), probe_spacing (m), probe_dims, face_texels (n),
// tiles_per_row; sampler probe_offset (xyz: each probe's relocation, m) where probes are placed. Probe p = ix + nx (iy + ny iz) owns a 3n x 2n tile, face f at column f % 3, row f / 3.
// Face f = 2 axis + (negative ? 1 : 0) looks along `forward`; its texel (i, j) along
// forward + s right + t up, s = 2 (i + 0.5) / n - 1, t likewise from j.

int probe_count() {
    return probe_dims.x * probe_dims.y * probe_dims.z;
}

int probe_index(ivec3 q) {
    return q.x + probe_dims.x * (q.y + probe_dims.y * q.z);
}

ivec3 probe_cell(int p) {
    return ivec3(p % probe_dims.x, (p / probe_dims.x) % probe_dims.y, p / (probe_dims.x * probe_dims.y));
}

// The SH table's / state texture's row of a probe: iy + ny iz.
int probe_row(ivec3 q) {
    return q.y + probe_dims.y * q.z;
}

// Where probe q sits: its grid position moved by its relocation offset (sampler probe_offset, the
// state's layout; all 0 without relocation, and x + 0 is x exactly). A macro, not a function: shaders
// that never place a probe (the projection, the classification) do not declare probe_first,
// probe_spacing and probe_offset.
#define probe_position(q) (probe_first + vec3(q) * probe_spacing + texelFetch(probe_offset, ivec2((q).x, probe_row(q)), 0).xyz)

// Texel (0, 0) of face `face` of probe p in an atlas of n x n faces (the capture's: n = face_texels).
ivec2 tile_origin(int p, int face, int n) {
    return ivec2(3 * n * (p % tiles_per_row) + n * (face % 3), 2 * n * (p / tiles_per_row) + n * (face / 3));
}

ivec2 face_origin(int p, int face) {
    return tile_origin(p, face, face_texels);
}

// The probe whose tile holds atlas texel px (the capture's atlas; the inverse of tile_origin); at least
// probe_count() for a texel past the last probe's tile.
int atlas_probe(ivec2 px) {
    ivec2 tile = px / ivec2(3 * face_texels, 2 * face_texels);
    return tile.x + tiles_per_row * tile.y;
}

void face_frame(int face, out vec3 forward, out vec3 right, out vec3 up) {
    float sgn = (face % 2 == 0) ? 1.0 : -1.0;
    int axis = face / 2;
    if (axis == 0) {
        forward = vec3(sgn, 0.0, 0.0);
        right = vec3(0.0, sgn, 0.0);
        up = vec3(0.0, 0.0, 1.0);
    } else if (axis == 1) {
        forward = vec3(0.0, sgn, 0.0);
        right = vec3(0.0, 0.0, sgn);
        up = vec3(1.0, 0.0, 0.0);
    } else {
        forward = vec3(0.0, 0.0, sgn);
        right = vec3(sgn, 0.0, 0.0);
        up = vec3(0.0, 1.0, 0.0);
    }
}

// Unit direction of face coordinates st in [-1, 1]^2.
vec3 face_direction(int face, vec2 st) {
    vec3 f, r, u;
    face_frame(face, f, r, u);
    return normalize(f + st.x * r + st.y * u);
}

vec2 texel_st(ivec2 ij) {
    return (vec2(ij) + 0.5) * (2.0 / float(face_texels)) - 1.0;
}

// Solid angle of the face-plane rectangle [0, x] x [0, y] at distance 1.
float corner_area(float x, float y) {
    return atan(x * y, sqrt(x * x + y * y + 1.0));
}

// Exact solid angle (sr) of texel ij of an n x n face (the paper's closed form).
float texel_solid_angle(ivec2 ij) {
    float h = 2.0 / float(face_texels);
    vec2 lo = vec2(ij) * h - 1.0;
    vec2 hi = lo + h;
    return corner_area(hi.x, hi.y) - corner_area(lo.x, hi.y) - corner_area(hi.x, lo.y) + corner_area(lo.x, lo.y);
}

// The face a direction falls on and its face coordinates st in [-1, 1]^2 (the major axis, as the
// rasterized faces partition directions).
int direction_face(vec3 d, out vec2 st) {
    vec3 a = abs(d);
    int face;
    if (a.x >= a.y && a.x >= a.z) {
        face = d.x >= 0.0 ? 0 : 1;
    } else if (a.y >= a.z) {
        face = d.y >= 0.0 ? 2 : 3;
    } else {
        face = d.z >= 0.0 ? 4 : 5;
    }
    vec3 f, r, u;
    face_frame(face, f, r, u);
    float w = dot(d, f);
    st = vec2(dot(d, r), dot(d, u)) / max(w, 1e-12);
    return face;
}

// Bilinear interpolation of an n x n face at direction d, within the face (clamped at its edges, no
// blend across faces): the face, the texels i0 and i1 (in the face) and the weights f of i1.
int face_bilinear(vec3 d, int n, out ivec2 i0, out ivec2 i1, out vec2 f) {
    vec2 st;
    int face = direction_face(d, st);
    vec2 uv = clamp((st + 1.0) * (0.5 * float(n)) - 0.5, vec2(0.0), vec2(float(n - 1)));
    i0 = ivec2(floor(uv));
    i1 = min(i0 + 1, ivec2(n - 1));
    f = uv - vec2(i0);
    return face;
}
