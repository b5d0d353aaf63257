// Points mode and the splat passes share this vertex shader: one GL point per input point,
// sized on screen from its splat radius (radius * pixels per unit / depth).
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec4 a_color;  // rgb, intensity byte in alpha (normalised)
layout(location = 2) in vec4 a_normal; // 2_10_10_10 signed normalised; zero when unknown
layout(location = 3) in float a_radius;
layout(location = 4) in uvec4 a_las;    // classification, return number, returns, flags
layout(location = 5) in float a_gpsTime; // relative to the cloud's base

uniform mat4 u_view;
uniform mat4 u_projection;
uniform float u_pixelsPerUnit; // viewport height / (2 tan(fovY / 2)); orthographic: per unit
uniform bool u_orthographic;
uniform float u_sizeScale;
uniform float u_minPointPx;
uniform float u_maxPointPx;
uniform float u_depthOffset; // splat visibility pass: push splats back by this many radii
uniform bool u_clipEnabled;
uniform mat4 u_clip; // unit cube -> clip box frame, inside = [-1, 1]^3

out vec3 v_color;
out vec3 v_viewNormal;
out float v_pointPx;

void main() {
    if ((u_clipEnabled &&
         any(greaterThan(abs((u_clip * vec4(a_position, 1.0)).xyz), vec3(1.0)))) ||
        classHidden(a_las.x)) {
        gl_Position = vec4(0.0, 0.0, 2.0, 1.0); // beyond the far plane: not drawn (clipped
                                                 // away, or of a hidden class)
        gl_PointSize = 1.0;
        v_color = vec3(0.0);
        v_viewNormal = vec3(0.0);
        v_pointPx = 0.0;
        return;
    }
    vec4 viewPosition = u_view * vec4(a_position, 1.0);
    float radius = a_radius * u_sizeScale;
    viewPosition.z -= u_depthOffset * radius;
    gl_Position = u_projection * viewPosition;
    float depth = u_orthographic ? 1.0 : max(-viewPosition.z, 1e-7);
    float pointPx = clamp(2.0 * radius * u_pixelsPerUnit / depth, u_minPointPx, u_maxPointPx);
    gl_PointSize = pointPx;
    v_pointPx = pointPx;
    v_color = pointColor(a_position, a_color, a_normal.xyz, a_las, a_gpsTime);
    v_viewNormal = mat3(u_view) * a_normal.xyz;
}
