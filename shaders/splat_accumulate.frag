// Splat pass 2 (accumulation): every splat within the visible surface adds its colour with a
// Gaussian weight of its distance from the centre; additive blending into a float target.
in vec3 v_color;
in vec3 v_viewNormal;
in float v_pointPx;

out vec4 accumulated;

void main() {
    float distance2 = splatDistance2(v_viewNormal);
    if (distance2 > 1.0) {
        discard;
    }
    float weight = exp(-2.5 * distance2);
    accumulated = vec4(v_color * weight, weight);
}
