// The quads of method `gather` (paper 001; docs/GATHER.md): texel corners on a probe's cube faces.
// Needs probes/probe.glsl. A face of n x n texels has (n + 1)^2 corners; corner (k, l) lies at the
// face-plane point forward + s right + t up with s = (2k - n) / n, t = (2l - n) / n. Written so, the
// coordinates are exact negatives of each other where two faces share an edge, and a corner gets the
// same direction from every face that holds it.

// Corner c (0..3) of a texel, counter-clockwise about the face's forward axis (right x up = forward):
// (0, 0), (1, 0), (1, 1), (0, 1) in (column, row) offsets from the texel's own index.
ivec2 corner_offset(int c) {
    return ivec2((c == 1 || c == 2) ? 1 : 0, c >= 2 ? 1 : 0);
}

// The corner index of offset o in {0, 1}^2 (the inverse of corner_offset).
int corner_of_offset(ivec2 o) {
    return o.y == 0 ? o.x : 3 - o.x;
}

// The unnormalised direction of corner k of a face of n texels a side: a point on the cube [-1, 1]^3.
vec3 corner_point(int face, ivec2 k, int n) {
    vec3 f, r, u;
    face_frame(face, f, r, u);
    return f + (float(2 * k.x - n) / float(n)) * r + (float(2 * k.y - n) / float(n)) * u;
}

// A texel's surface as a plane: `plane` = (unit normal towards the probe, n . (surface point - probe)),
// the offset <= 0 (gather/texels.comp.glsl). At 8^2 texels a face a texel spans ~11 degrees, and a plane
// within 20 degrees of edge-on runs past 4 x the texel's own distance along a corner's direction, or
// never meets it: there one normal no longer says where the surface is.
const float GRAZING_LIMIT = 4.0;

// Where the texel's plane meets its corner direction `corner` (unit; `centre` the texel's centre
// direction, unit), relative to the probe: on the plane and at most GRAZING_LIMIT x the centre's
// distance along the way, so a plane seen near edge-on gives a quad that stays in its plane (a
// receiver on that plane then sees it edge-on, as it sees the surface) instead of one that floats
// off it. `clipped` says the corner was pulled in: the texel cannot vouch for that direction.
vec3 plane_corner(vec4 plane, vec3 centre, vec3 corner, out bool clipped) {
    float along_centre = dot(plane.xyz, centre);  // < 0: the probe sees the plane's front
    vec3 e = corner - centre;
    float along_e = dot(plane.xyz, e);
    // Along u(s) = centre + s e the plane is met at plane.w / (n . u(s)); n . u(s) <= n . centre /
    // GRAZING_LIMIT keeps that within the limit (|u(s)| <= 1).
    float s = 1.0;
    if (along_e > 0.0) {
        s = min(1.0, along_centre * (1.0 / GRAZING_LIMIT - 1.0) / along_e);
    }
    clipped = s < 1.0;
    vec3 u = centre + s * e;
    return u * (plane.w / dot(plane.xyz, u));
}
