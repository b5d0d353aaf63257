// Splat pass 1 (visibility): depth of the nearest surface, splats pushed back slightly (by the
// vertex shader's u_depthOffset) so that the splats of the same surface blend in pass 2.
in vec3 v_color;
in vec3 v_viewNormal;
in float v_pointPx;

void main() {
    if (splatDistance2(v_viewNormal) > 1.0) {
        discard;
    }
}
