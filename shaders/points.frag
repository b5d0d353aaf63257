// Points mode: a round point (screen-aligned disc), opaque, written to depth.
in vec3 v_color;
in vec3 v_viewNormal;
in float v_pointPx;

out vec4 fragColor;

void main() {
    vec2 offset = gl_PointCoord * 2.0 - 1.0;
    if (v_pointPx > 2.0 && dot(offset, offset) > 1.0) {
        discard;
    }
    fragColor = vec4(v_color, 1.0);
}
