// ViewCamera: the navigation math, without a GL context.
#include "render_settings.hpp"
#include "view_camera.hpp"

#include <QtTest>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

using namespace omicron;

namespace {

glm::dvec3 project(const ViewCamera& camera, const glm::dvec3& point) {
    const glm::dvec4 clip = camera.projectionMatrix(1.0) * camera.viewMatrix() * glm::dvec4(point, 1.0);
    return glm::dvec3(clip) / clip.w;
}

bool insideClip(const glm::dvec3& ndc) {
    return std::abs(ndc.x) <= 1.0 && std::abs(ndc.y) <= 1.0 && std::abs(ndc.z) <= 1.0;
}

} // namespace

class tst_ViewCamera : public QObject {
    Q_OBJECT
private slots:
    void fitShowsEveryCornerOfTheBox() {
        ViewCamera camera;
        camera.setSceneBox({0.0, 0.0, 0.0}, {1.0, 0.5, 0.2});
        for (StandardView view : {StandardView::Top, StandardView::Front, StandardView::Left,
                                  StandardView::Iso, StandardView::Back, StandardView::Bottom}) {
            camera.setStandardView(view);
            for (int i = 0; i < 8; ++i) {
                const glm::dvec3 corner(i & 1 ? 1.0 : 0.0, i & 2 ? 0.5 : 0.0, i & 4 ? 0.2 : 0.0);
                QVERIFY2(insideClip(project(camera, corner)), "a box corner is outside the view");
            }
        }
    }

    void topViewLooksDown() {
        ViewCamera camera;
        camera.setStandardView(StandardView::Top);
        QVERIFY(camera.forward().z < -0.999);
        camera.setStandardView(StandardView::Front);
        QVERIFY(std::abs(camera.forward().z) < 1e-9);
        QVERIFY(camera.forward().y > 0.999); // from the front (-y side) towards +y
    }

    void orbitKeepsThePivotAndDistance() {
        ViewCamera camera;
        camera.setPose({0.3, 0.4, 0.5}, 2.0, 0.1, 0.2);
        camera.orbit(120.0, -45.0);
        QCOMPARE(camera.pivot(), glm::dvec3(0.3, 0.4, 0.5));
        QVERIFY(std::abs(glm::length(camera.eye() - camera.pivot()) - 2.0) < 1e-9);
        camera.orbit(0.0, 100000.0); // pitch is clamped short of the pole
        QVERIFY(camera.pitchRadians() < 3.14159265 / 2.0);
        QVERIFY(std::isfinite(camera.viewMatrix()[0][0]));
    }

    void zoomTowardMovesTheTargetNowhere() {
        ViewCamera camera;
        camera.setPose({0.5, 0.5, 0.5}, 2.0, 0.3, 0.4);
        const glm::dvec3 target(0.6, 0.45, 0.5);
        const glm::dvec3 before = project(camera, target);
        camera.zoomToward(target, 0.5);
        const glm::dvec3 after = project(camera, target);
        // The point under the cursor stays under the cursor.
        QVERIFY(std::abs(before.x - after.x) < 1e-9 && std::abs(before.y - after.y) < 1e-9);
        QVERIFY(std::abs(camera.distance() - 1.0) < 1e-9);
    }

    void panMovesThePivotWithTheMouse() {
        ViewCamera camera;
        camera.setPose({0.5, 0.5, 0.5}, 2.0, 0.0, 0.0);
        const glm::dvec3 marker(0.5, 0.5, 0.5);
        camera.pan(100.0, 0.0, 800.0);
        // Dragging right moves the scene right: the old pivot now projects right of centre.
        QVERIFY(project(camera, marker).x > 0.0);
        QVERIFY(std::abs(project(camera, marker).y) < 1e-9);
    }

    void setPivotKeepsTheEye() {
        ViewCamera camera;
        camera.setPose({0.5, 0.5, 0.5}, 2.0, 0.7, 0.3);
        const glm::dvec3 eye = camera.eye();
        camera.setPivot({0.2, 0.8, 0.1});
        QVERIFY(glm::length(camera.eye() - eye) < 1e-9);
        QVERIFY(glm::length(camera.pivot() - glm::dvec3(0.2, 0.8, 0.1)) < 1e-12);
    }

    void flyMovesEyeAndPivotTogether() {
        ViewCamera camera;
        camera.setSceneBox({0, 0, 0}, {1, 1, 1});
        camera.setPose({0.5, 0.5, 0.5}, 1.0, 0.0, 0.0);
        const glm::dvec3 forward = camera.forward();
        const glm::dvec3 eye = camera.eye();
        camera.fly({0.0, 0.0, 1.0}, 1.0); // W for one second
        QVERIFY(glm::length(camera.eye() - (eye + forward * camera.flySpeed())) < 1e-9);
        QVERIFY(std::abs(camera.distance() - 1.0) < 1e-12);
        camera.look(50.0, 0.0);
        QVERIFY(glm::length(camera.eye() - (eye + forward * camera.flySpeed())) < 1e-9);
    }
};

QTEST_APPLESS_MAIN(tst_ViewCamera)
#include "tst_viewcamera.moc"
