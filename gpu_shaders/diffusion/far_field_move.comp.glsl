// Diffusion far field, enclosed cells: the far grid's starting light (the fine grid's light in flight
// summed per far cell, lpv_far_field.source, in src_r/g/b) with the light of every enclosed cell -
// occupied, no open face - moved to its neighbours (passes/diffusion_far_field.py; twin:
// diffusion_reference.far_move_enclosed). Light leaves an occupied cell only by open faces, and where a
// wall meets a floor or ceiling the far cell on the edge is walled in by occupied cells (wall, floor and
// the edge cells beside it) though the fine light in it is in the room: summing the fine emitters into
// the far grid trapped a quarter of thin-wall's wall light there.
// An enclosed cell's light goes to its 18 face and edge neighbours that are not enclosed, in proportion
// to 1e-3 + max(0, u.w), u the unit offset, w the mean direction of its light (the band-1 vector of its
// channels' sum): mostly to the room diagonal it faces, keeping its direction of travel. With no such
// neighbour it stays (and is lost, as before). Every cell written; `dims` are the far grid's.
#include "diffusion/cell.glsl"

bool enclosed(ivec3 c) {
    vec4 block = texelFetch(cell_block, c, 0);
    return diffusion_occupied(block) && ((int(block.w) - 1) & 63) == 0;
}

// The 18 offsets of the face and edge neighbours: i = 0..26 over the 3 x 3 x 3 block, skipping the centre
// and the corners (Manhattan length 0 or 3).
ivec3 block_offset(int i) {
    return ivec3(i % 3, (i / 3) % 3, i / 9) - 1;
}

bool face_or_edge(ivec3 o) {
    int l = abs(o.x) + abs(o.y) + abs(o.z);
    return l == 1 || l == 2;
}

float move_weight(ivec3 o, vec3 w) {
    return 1e-3 + max(0.0, dot(normalize(vec3(o)), w));
}

// The mean direction of the light in cell c (unit, or 0): band 1 (y, z, x) of its channels' sum; a cone
// field's (CONE, cone_fields.py), whose coefficients are of the cone's own basis: the cone's axis.
vec3 light_direction(ivec3 c) {
#ifdef CONE
    return diffusion_direction(CONE);
#endif
    vec4 s = texelFetch(src_r, c, 0) + texelFetch(src_g, c, 0) + texelFetch(src_b, c, 0);
    vec3 w = s.wyz;
    float l = length(w);
    return l > 0.0 ? w / l : vec3(0.0);
}

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, dims))) {
        return;
    }
    vec4 r = vec4(0.0), g = vec4(0.0), b = vec4(0.0);
    bool stays = !enclosed(c);
    if (!stays) {  // does any neighbour take its light?
        stays = true;
        for (int i = 0; i < 27; ++i) {
            ivec3 n = c + block_offset(i);
            if (face_or_edge(block_offset(i)) && diffusion_inside(n) && !enclosed(n)) {
                stays = false;
            }
        }
    }
    if (stays) {
        r = texelFetch(src_r, c, 0);
        g = texelFetch(src_g, c, 0);
        b = texelFetch(src_b, c, 0);
    }
    if (!enclosed(c)) {
        for (int i = 0; i < 27; ++i) {
            ivec3 o = block_offset(i);
            ivec3 e = c - o;  // the neighbour whose offset to c is o
            if (!face_or_edge(o) || !diffusion_inside(e) || !enclosed(e)) {
                continue;
            }
            vec3 w = light_direction(e);
            float total = 0.0;
            for (int j = 0; j < 27; ++j) {
                ivec3 n = e + block_offset(j);
                if (face_or_edge(block_offset(j)) && diffusion_inside(n) && !enclosed(n)) {
                    total += move_weight(block_offset(j), w);
                }
            }
            float share = move_weight(o, w) / total;  // total >= this term > 0
            r += share * texelFetch(src_r, e, 0);
            g += share * texelFetch(src_g, e, 0);
            b += share * texelFetch(src_b, e, 0);
        }
    }
    imageStore(sh_r, c, r);
    imageStore(sh_g, c, g);
    imageStore(sh_b, c, b);
}
