// Flux per face of a cell (faces 0..5 as +x -x +y -y +z -z, rgb each: 18 numbers) packed into five RGBA
// texels, number 3 f + channel at texel (3 f + channel) / 4, component (3 f + channel) % 4: the far
// field's absorbed flux by the face it came through (diffusion_far_field). Read back in tests/gpu/test_diffusion.py::faces_of.

void diffusion_pack_faces(vec3 a0, vec3 a1, vec3 a2, vec3 a3, vec3 a4, vec3 a5,
                          out vec4 p0, out vec4 p1, out vec4 p2, out vec4 p3, out vec4 p4) {
    p0 = vec4(a0, a1.r);
    p1 = vec4(a1.gb, a2.rg);
    p2 = vec4(a2.b, a3);
    p3 = vec4(a4, a5.r);
    p4 = vec4(a5.gb, 0.0, 0.0);
}

// Face f's rgb from the five texels p0..p4.
vec3 diffusion_unpack_face(int f, vec4 p0, vec4 p1, vec4 p2, vec4 p3, vec4 p4) {
    return f == 0 ? p0.rgb : f == 1 ? vec3(p0.a, p1.rg) : f == 2 ? vec3(p1.ba, p2.r)
         : f == 3 ? p2.gba : f == 4 ? p3.rgb : vec3(p3.a, p4.rg);
}
