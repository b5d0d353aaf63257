// The surface splat under a fragment of its point sprite: the sprite spans the splat's radius
// in view space, the splat is a disc orthogonal to its normal, so a sprite offset (x, y) lies
// on the disc at depth z = -(n.x x + n.y y) / n.z. Returns the squared distance from the
// splat centre in radii (> 1: outside the disc). Unknown normals give a screen-aligned disc.
float splatDistance2(vec3 viewNormal) {
    vec2 offset = gl_PointCoord * 2.0 - 1.0;
    offset.y = -offset.y; // gl_PointCoord grows downwards
    vec3 n = length(viewNormal) > 0.0 ? normalize(viewNormal) : vec3(0.0, 0.0, 1.0);
    if (n.z < 0.0) {
        n = -n; // the side facing the camera
    }
    float nz = max(n.z, 0.2); // very oblique splats: a thin ellipse, not an infinite one
    float z = -(n.x * offset.x + n.y * offset.y) / nz;
    return dot(offset, offset) + z * z;
}
