// NodeBufferCache under a real GL context: nodes share large page buffers (what lets the
// compute rasterizer draw many nodes per dispatch), free ranges are reused and coalesced,
// empty pages are deleted, and the uploaded bytes are the nodes' vertices.
#include "node_buffer_cache.hpp"

#include <QOffscreenSurface>
#include <QOpenGLContext>
#include <QtTest>
#include <cstring>
#include <memory>

using namespace omicron;

namespace {

std::vector<PointVertex> vertices(std::size_t count, float tag) {
    std::vector<PointVertex> result(count);
    for (std::size_t i = 0; i < count; ++i) {
        result[i].x = tag;
        result[i].y = static_cast<float>(i);
        result[i].radius = 0.5f;
    }
    return result;
}

} // namespace

class tst_NodeBufferCacheGL : public QObject {
    Q_OBJECT

    std::unique_ptr<QOpenGLContext> m_context;
    std::unique_ptr<QOffscreenSurface> m_surface;

    QOpenGLExtraFunctions& gl() { return *m_context->extraFunctions(); }

    // The vertices a buffer holds for `buffer` (read back from its page).
    std::vector<PointVertex> readBack(const NodeBufferCache::Buffer& buffer) {
        std::vector<PointVertex> result(static_cast<std::size_t>(buffer.pointCount));
        gl().glBindBuffer(GL_ARRAY_BUFFER, buffer.vbo);
        const void* mapped = gl().glMapBufferRange(
            GL_ARRAY_BUFFER, static_cast<GLintptr>(buffer.firstPoint * sizeof(PointVertex)),
            static_cast<GLsizeiptr>(result.size() * sizeof(PointVertex)), GL_MAP_READ_BIT);
        if (mapped != nullptr) {
            std::memcpy(result.data(), mapped, result.size() * sizeof(PointVertex));
        }
        gl().glUnmapBuffer(GL_ARRAY_BUFFER);
        gl().glBindBuffer(GL_ARRAY_BUFFER, 0);
        return result;
    }

private slots:
    void initTestCase() {
        QSurfaceFormat format;
        format.setVersion(3, 3);
        format.setProfile(QSurfaceFormat::CoreProfile);
        m_context = std::make_unique<QOpenGLContext>();
        m_context->setFormat(format);
        QVERIFY(m_context->create());
        m_surface = std::make_unique<QOffscreenSurface>();
        m_surface->setFormat(m_context->format());
        m_surface->create();
        QVERIFY(m_context->makeCurrent(m_surface.get()));
    }

    void cleanupTestCase() {
        m_context->doneCurrent();
        m_context.reset();
        m_surface.reset();
    }

    void nodesShareAPageUntilItIsFull() {
        NodeBufferCache cache;
        cache.setPagePoints(100);
        const auto& a = cache.upload(gl(), 1, vertices(40, 1.0f), 1);
        const auto& b = cache.upload(gl(), 2, vertices(60, 2.0f), 1);
        QCOMPARE(a.vbo, b.vbo);
        QCOMPARE(a.firstPoint, 0);
        QCOMPARE(b.firstPoint, 40);
        const auto& c = cache.upload(gl(), 3, vertices(30, 3.0f), 1);
        QVERIFY(c.vbo != a.vbo);
        QCOMPARE(cache.pageCount(), std::size_t{2});
        QCOMPARE(cache.bytesResident(), std::size_t{130} * sizeof(PointVertex));
        for (const auto* buffer : {&a, &b, &c}) {
            const auto back = readBack(*buffer);
            QCOMPARE(back.size(), static_cast<std::size_t>(buffer->pointCount));
            for (std::size_t i = 0; i < back.size(); ++i) {
                QCOMPARE(back[i].x, static_cast<float>(buffer == &a ? 1 : buffer == &b ? 2 : 3));
                QCOMPARE(back[i].y, static_cast<float>(i));
            }
        }
        cache.clear(gl());
        QCOMPARE(cache.pageCount(), std::size_t{0});
        QCOMPARE(cache.bytesResident(), std::size_t{0});
    }

    void evictionFreesAndCoalescesRanges() {
        NodeBufferCache cache;
        cache.setPagePoints(100);
        cache.upload(gl(), 1, vertices(30, 1.0f), 1);
        cache.upload(gl(), 2, vertices(30, 2.0f), 1);
        cache.upload(gl(), 3, vertices(40, 3.0f), 2);
        QCOMPARE(cache.pageCount(), std::size_t{1});
        // Nodes 1 and 2 were drawn longest ago: they go first, and their ranges merge.
        QCOMPARE(cache.evictTo(gl(), 40 * sizeof(PointVertex), 2), std::size_t{2});
        QVERIFY(cache.use(1, 3) == nullptr);
        QVERIFY(cache.use(3, 3) != nullptr);
        const auto& d = cache.upload(gl(), 4, vertices(60, 4.0f), 3);
        QCOMPARE(cache.pageCount(), std::size_t{1});
        QCOMPARE(d.firstPoint, 0);
        QCOMPARE(readBack(d).back().x, 4.0f);
        QCOMPARE(readBack(*cache.use(3, 3)).front().x, 3.0f); // untouched by the reuse
        // The last node of a page gone: the page is deleted.
        QCOMPARE(cache.evictTo(gl(), 0, 4), std::size_t{2});
        QCOMPARE(cache.pageCount(), std::size_t{0});
        QCOMPARE(cache.bytesResident(), std::size_t{0});
    }

    void largeNodesGetTheirOwnPageAndReuploadsMove() {
        NodeBufferCache cache;
        cache.setPagePoints(100);
        const auto& big = cache.upload(gl(), 1, vertices(250, 1.0f), 1);
        QCOMPARE(big.firstPoint, 0);
        QCOMPARE(big.pointCount, 250);
        QCOMPARE(readBack(big)[249].y, 249.0f);
        const auto& small = cache.upload(gl(), 2, vertices(10, 2.0f), 1);
        QVERIFY(small.vbo != big.vbo);
        // The same node uploaded again with another size: one entry, the new bytes.
        const auto& again = cache.upload(gl(), 2, vertices(20, 5.0f), 2);
        QCOMPARE(cache.size(), std::size_t{2});
        QCOMPARE(again.pointCount, 20);
        QCOMPARE(readBack(again)[19].x, 5.0f);
        QCOMPARE(cache.bytesResident(), std::size_t{270} * sizeof(PointVertex));
        cache.clear(gl());
    }
};

QTEST_MAIN(tst_NodeBufferCacheGL)
#include "tst_nodebuffercache_gl.moc"
