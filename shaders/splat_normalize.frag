// Splat pass 3 (normalisation): weighted colour sum / weight sum, with the visibility pass's
// depth so overlays drawn afterwards are hidden by the surface.
in vec2 v_uv;

uniform sampler2D u_accumulation;
uniform sampler2D u_depth;

out vec4 fragColor;

void main() {
    vec4 sum = texture(u_accumulation, v_uv);
    if (sum.a <= 0.0) {
        discard;
    }
    fragColor = vec4(sum.rgb / sum.a, 1.0);
    gl_FragDepth = texture(u_depth, v_uv).r;
}
