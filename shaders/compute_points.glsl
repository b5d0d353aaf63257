// Compute point rasterizer (after Schütz, Kerbl and Wimmer, "Rendering Point Clouds with
// Compute Shaders and Vertex Order Optimization", 2021), shared by its two passes: one
// invocation per point projects it like points.vert does and visits the pixels of the same
// round footprint GL_POINTS would cover, calling the pass's visitPixel() for each.
//
// A dispatch covers every drawn node of one page of node vertices: invocations are numbered
// through the nodes in draw-table order, and each workgroup finds its first node in the chunk
// table (nodes are many and small: a dispatch per node would cost more than its points).
//
// Inputs are buffer textures, not storage buffers: Mesa llvmpipe turns every storage-buffer
// load into a loop over the SIMD lanes, a texel fetch into one vector gather (measured at a 1M
// point budget: 53 instead of 64 ms of CPU time per pass). The per-pixel buffers are images:
// the resolve pass samples them as textures, and a framebuffer clear empties them.
layout(local_size_x = 128) in;

// The page of node vertices (node_vertices.hpp: 32 bytes = 2 RGBA32UI texels per point), the
// frame's draw table (DrawNode below, one RGBA32UI texel each) and, per workgroup of
// 128 invocations, the draw-table entry (from u_nodeBase) that holds its first invocation.
uniform highp usamplerBuffer u_pagePoints;
uniform highp usamplerBuffer u_drawNodes;
uniform highp usamplerBuffer u_chunkNodes;

// Per pixel (GL's orientation, bottom row first): the nearest window depth as float bits
// (non-negative floats order like their bits; 0xffffffff = empty) and that point's colour.
layout(r32ui, binding = 0) uniform coherent highp uimage2D u_depthImage;

uniform mat4 u_view;
uniform mat4 u_viewProjection;
uniform float u_pixelsPerUnit; // orthographic: pixels per unit anywhere
uniform bool u_orthographic;
uniform float u_sizeScale;
uniform float u_minPointPx;
uniform float u_maxPointPx;
uniform ivec2 u_viewportPx;
uniform bool u_clipEnabled;
uniform mat4 u_clip; // unit cube -> clip box frame, inside = [-1, 1]^3
uniform uint u_pointCount; // invocations of this dispatch: the points of its nodes
uniform uint u_nodeBase;   // its nodes in the draw table (followed by a sentinel entry)
uniform uint u_chunkBase;  // its workgroups in the chunk table

struct PointVertex {
    vec3 position;
    uint color;  // r, g, b, intensity bytes (r lowest)
    uint normal; // GL_INT_2_10_10_10_REV, signed normalised
    float radius;
    uint las;    // classification, return number, number of returns, flags bytes (lowest first)
    float gpsTime;
};

struct DrawNode {
    uint firstInvocation; // of the dispatch
    uint firstPoint;      // in the page
    uint levelColor;      // RGBA8 (level colour mode)
    float buildAge;       // build-age colour mode
};

struct Footprint {
    vec2 centrePx;  // window coordinates
    float sizePx;   // diameter, as gl_PointSize
    uint depthBits; // window depth in [0, 1], as bits
};

PointVertex loadPoint(uint index) {
    uvec4 a = texelFetch(u_pagePoints, int(2u * index));
    uvec4 b = texelFetch(u_pagePoints, int(2u * index + 1u));
    return PointVertex(uintBitsToFloat(a.xyz), a.w, b.x, uintBitsToFloat(b.y), b.z,
                       uintBitsToFloat(b.w));
}

// The LAS bytes of a vertex as color.glsl takes them.
uvec4 lasBytes(PointVertex p) {
    return uvec4(p.las, p.las >> 8u, p.las >> 16u, p.las >> 24u) & 0xffu;
}

DrawNode loadDrawNode(uint index) {
    uvec4 words = texelFetch(u_drawNodes, int(index));
    return DrawNode(words.x, words.y, words.z, uintBitsToFloat(words.w));
}

// Large dispatches span a second grid dimension (at most 65535 groups per dimension).
uint invocationIndex() {
    return gl_WorkGroupID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x + gl_GlobalInvocationID.x;
}

// The draw-table entry of `invocation`: its workgroup's first node, then forward over nodes
// that end before it (the entry after a dispatch's last node is a sentinel at u_pointCount).
uint drawNodeOf(uint invocation) {
    int chunk = int(u_chunkBase + invocation / gl_WorkGroupSize.x);
    uint node = u_nodeBase + texelFetch(u_chunkNodes, chunk).x;
    while (texelFetch(u_drawNodes, int(node + 1u)).x <= invocation) {
        ++node;
    }
    return node;
}

vec3 decodeNormal(uint bits) {
    ivec3 c = ivec3(bitfieldExtract(int(bits), 0, 10), bitfieldExtract(int(bits), 10, 10),
                    bitfieldExtract(int(bits), 20, 10));
    return max(vec3(c) / 511.0, vec3(-1.0)); // the GL 4.2 rule for signed normalised values
}

// As points.vert: false when the point is clipped (outside the clip box, of a hidden class,
// behind the eye, outside near/far).
bool projectPoint(PointVertex p, out Footprint footprint) {
    if (u_clipEnabled &&
        any(greaterThan(abs((u_clip * vec4(p.position, 1.0)).xyz), vec3(1.0)))) {
        return false; // outside the clip box
    }
    if (classHidden(p.las & 0xffu)) {
        return false;
    }
    vec4 clip = u_viewProjection * vec4(p.position, 1.0);
    if (clip.w <= 0.0) {
        return false;
    }
    vec3 ndc = clip.xyz / clip.w;
    if (ndc.z < -1.0 || ndc.z > 1.0) {
        return false;
    }
    // Distance along the view axis: minus the view-space z (third row of u_view).
    float viewZ = dot(vec4(u_view[0][2], u_view[1][2], u_view[2][2], u_view[3][2]),
                      vec4(p.position, 1.0));
    float depth = u_orthographic ? 1.0 : max(-viewZ, 1e-7);
    float radius = p.radius * u_sizeScale;
    footprint.sizePx = clamp(2.0 * radius * u_pixelsPerUnit / depth, u_minPointPx, u_maxPointPx);
    footprint.centrePx = (ndc.xy * 0.5 + 0.5) * vec2(u_viewportPx);
    footprint.depthBits = floatBitsToUint(ndc.z * 0.5 + 0.5) & 0x7fffffffu; // no -0.0
    return true;
}

void visitPixel(ivec2 pixel, uint depthBits);

// The fragments GL_POINTS generates: pixel centres inside the point's square, and for points
// wider than 2 px (points.frag) only those inside its inscribed disc, visited row by row.
void rasterize(Footprint footprint) {
    vec2 c = footprint.centrePx - 0.5; // pixel p's centre is p + 0.5
    if (footprint.sizePx <= 1.0) {
        // One pixel, most points at a large point budget: no loops.
        ivec2 pixel = ivec2(ceil(c - 0.5));
        if (all(greaterThanEqual(pixel, ivec2(0))) && all(lessThan(pixel, u_viewportPx))) {
            visitPixel(pixel, footprint.depthBits);
        }
        return;
    }
    float halfPx = footprint.sizePx * 0.5;
    bool round = footprint.sizePx > 2.0;
    int y0 = max(int(ceil(c.y - halfPx)), 0);
    int y1 = min(int(ceil(c.y + halfPx)) - 1, u_viewportPx.y - 1);
    for (int y = y0; y <= y1; ++y) {
        int x0, x1;
        if (round) {
            float dy = float(y) - c.y;
            float reach2 = halfPx * halfPx - dy * dy;
            if (reach2 < 0.0) {
                continue;
            }
            float reach = sqrt(reach2);
            x0 = int(ceil(c.x - reach));
            x1 = int(floor(c.x + reach));
        } else {
            x0 = int(ceil(c.x - halfPx));
            x1 = int(ceil(c.x + halfPx)) - 1;
        }
        x0 = max(x0, 0);
        x1 = min(x1, u_viewportPx.x - 1);
        for (int x = x0; x <= x1; ++x) {
            visitPixel(ivec2(x, y), footprint.depthBits);
        }
    }
}
