// Compute points, pass 1: the nearest depth of every pixel, by 32-bit atomicMin.
void visitPixel(ivec2 pixel, uint depth) {
    // A plain read first: occluded fragments (most of them in a dense cloud) skip the atomic.
    if (depth < imageLoad(u_depthImage, pixel).x) {
        imageAtomicMin(u_depthImage, pixel, depth);
    }
}

void main() {
    uint invocation = invocationIndex();
    if (invocation >= u_pointCount) {
        return;
    }
    DrawNode node = loadDrawNode(drawNodeOf(invocation));
    Footprint footprint;
    if (projectPoint(loadPoint(node.firstPoint + invocation - node.firstInvocation), footprint)) {
        rasterize(footprint);
    }
}
