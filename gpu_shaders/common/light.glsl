// Light emission in Cycles' units, shared by the RSM and the direct-light pass.
// kind: 0 point/spot (intensity = power / (4 pi) * colour, W/sr; a spot masks it by its cone),
//       1 sun (intensity = irradiance W/m^2 normal to the light), 2 area (Lambertian: power / pi * cos).
const int LIGHT_POINT = 0;
const int LIGHT_SUN = 1;
const int LIGHT_AREA = 2;

// Spot cone mask of Cycles 5.0: smoothstep((cos t - cos(size/2)) / ((1 - cos(size/2)) * blend)),
// hard-edged when blend = 0. A point light has cos_half = -1 (no mask).
float spot_mask(vec3 emit_dir, vec3 axis, float cos_half, float blend) {
    float cos_t = dot(emit_dir, axis);
    if (cos_half <= -1.0) {
        return 1.0;
    }
    float x = (cos_t - cos_half) / max((1.0 - cos_half) * blend, 1e-9);
    return blend > 0.0 ? smoothstep(0.0, 1.0, x) : step(cos_half, cos_t);
}

// Radiant intensity (W/sr, per colour channel) leaving the light in direction emit_dir.
vec3 light_intensity(int kind, vec3 emit_dir, vec3 axis, vec3 intensity, float cos_half, float blend) {
    if (kind == LIGHT_AREA) {
        return intensity * max(dot(emit_dir, axis), 0.0);
    }
    return intensity * spot_mask(emit_dir, axis, cos_half, blend);
}
