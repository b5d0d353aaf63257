// Eye-dome lighting (a full-screen triangle over the drawn cloud): each pixel is darkened by
// how far its neighbours at a few pixels' distance lie in front of it, in log2 of the linear
// depth, so the shape of a cloud without colours reads at once (Boucheny's EDL as Potree and
// CloudCompare use it). Depth goes back into the frame for overlays drawn afterwards.
uniform sampler2D u_color;
uniform sampler2D u_depth;
uniform vec2 u_pixel;      // one pixel in texture coordinates
uniform float u_radius;    // neighbour distance, pixels
uniform float u_strength;  // 0: no shading
uniform float u_p22;       // projection matrix [2][2] and [3][2]: linear depth from the buffer
uniform float u_p32;
uniform bool u_orthographic; // the depth buffer is linear already

in vec2 v_uv;
out vec4 fragColor;

// log2 of the distance along the view axis; 0 for the background. Orthographic: of the
// distance from the far plane's opposite, kept positive (its differences are what shade).
float logDepth(vec2 uv) {
    float depth = texture(u_depth, uv).r;
    if (depth >= 1.0) {
        return 0.0;
    }
    float ndc = 2.0 * depth - 1.0;
    float distance = u_orthographic ? (ndc - u_p32) / -u_p22 + 2.0 / abs(u_p22)
                                    : u_p32 / (ndc + u_p22);
    return log2(max(distance, 1e-6));
}

void main() {
    // The target is cleared to alpha 0 and every pass of the cloud writes alpha 1: coverage
    // comes from the colour (a splat's edge may be drawn where the surface depth is not).
    vec4 color = texture(u_color, v_uv);
    if (color.a == 0.0) {
        discard; // background stays as cleared
    }
    float depth = texture(u_depth, v_uv).r;
    float center = logDepth(v_uv);
    const vec2 directions[8] = vec2[](vec2(1, 0), vec2(0.7071, 0.7071), vec2(0, 1),
                                     vec2(-0.7071, 0.7071), vec2(-1, 0), vec2(-0.7071, -0.7071),
                                     vec2(0, -1), vec2(0.7071, -0.7071));
    float response = 0.0;
    for (int i = 0; i < 8 && center != 0.0; ++i) {
        float neighbour = logDepth(v_uv + directions[i] * u_radius * u_pixel);
        if (neighbour != 0.0) {
            response += max(0.0, center - neighbour);
        }
    }
    float shade = exp(-response / 8.0 * 300.0 * u_strength);
    fragColor = vec4(color.rgb * shade, 1.0);
    gl_FragDepth = depth;
}
