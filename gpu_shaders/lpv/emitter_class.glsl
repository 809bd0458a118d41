// Emitter class of a normal: its dominant axis and sign, 2 * axis + (negative ? 1 : 0), so +x -x +y -y
// +z -z are 0..5 (lpv_inject.emitter_class is the twin; ties go to the earlier axis, a zero normal is
// +x). Two surfaces of one class face within 90 degrees of one axis: for planar surfaces neither can
// light the other, which the LPV's emitter classes use (docs/LPV.md, "Emitter classes").
int emitter_class(vec3 n) {
    vec3 a = abs(n);
    int axis = (a.x >= a.y && a.x >= a.z) ? 0 : (a.y >= a.z ? 1 : 2);
    return 2 * axis + (n[axis] < 0.0 ? 1 : 0);
}
