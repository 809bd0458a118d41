// Viewport overlay: one triangle that covers the whole region (corners (-1,-1), (3,-1), (-1,3)), so no
// diagonal seam and no view matrix: the overlay's images were rendered with the region's own camera.
void main() {
    gl_Position = vec4(pos_ndc, 0.0, 1.0);
    uv = pos_ndc * 0.5 + 0.5;  // GL convention: row 0 = bottom, as the images are stored
}
