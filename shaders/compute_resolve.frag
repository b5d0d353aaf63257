// Compute points, pass 3 (a full-screen triangle): each covered pixel's colour and depth into
// the frame, so overlays drawn afterwards and picking see the points.
uniform highp usampler2D u_depth; // float bits; 0xffffffff where no point is
uniform sampler2D u_color;

out vec4 fragColor;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    uint depth = texelFetch(u_depth, pixel, 0).x;
    if (depth == 0xffffffffu) {
        discard;
    }
    fragColor = vec4(texelFetch(u_color, pixel, 0).rgb, 1.0);
    gl_FragDepth = uintBitsToFloat(depth);
}
