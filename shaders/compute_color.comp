// Compute points, pass 2: the points whose depth won a pixel in pass 1 write their colour
// there (the same footprint again; points of exactly equal depth race for the pixel, and
// either colour is a right answer).
layout(rgba8, binding = 1) uniform writeonly highp image2D u_colorImage;

vec4 g_color;

void visitPixel(ivec2 pixel, uint depth) {
    if (imageLoad(u_depthImage, pixel).x == depth) {
        imageStore(u_colorImage, pixel, g_color);
    }
}

void main() {
    uint invocation = invocationIndex();
    if (invocation >= u_pointCount) {
        return;
    }
    DrawNode node = loadDrawNode(drawNodeOf(invocation));
    PointVertex p = loadPoint(node.firstPoint + invocation - node.firstInvocation);
    Footprint footprint;
    if (!projectPoint(p, footprint)) {
        return;
    }
    g_color = vec4(pointColorOf(p.position, unpackUnorm4x8(p.color), decodeNormal(p.normal),
                                lasBytes(p), p.gpsTime, unpackUnorm4x8(node.levelColor).rgb,
                                node.buildAge),
                   1.0);
    rasterize(footprint);
}
