// Integer hash (lowbias32-style finaliser) and a uniform float in [0, 1) from three integers: per-pixel
// random numbers that are the same on every backend (no driver noise functions).
uint hash_u32(uint x) {
    x ^= x >> 16u;
    x *= 0x7feb352du;
    x ^= x >> 15u;
    x *= 0x846ca68bu;
    x ^= x >> 16u;
    return x;
}

float random01(uint a, uint b, uint c) {
    return float(hash_u32(a ^ hash_u32(b ^ hash_u32(c))) >> 8u) * (1.0 / 16777216.0);
}
