// ClipPanel: the Clipping dock. Turns the view's clip box on and off and edits it with numeric
// fields in the file's coordinates: a box (centre, size, turn about the vertical) or a section
// (a slab of the given thickness through the centre, across the turned x axis, unbounded
// along the plane). Fit to the cloud, or centre on the last point picked in the view.
#pragma once

#include "points/clip_box.hpp"

#include <QWidget>
#include <optional>

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;

namespace omicron {

class ClipPanel : public QWidget {
    Q_OBJECT
public:
    // A section's extent along its plane: larger than any survey.
    static constexpr double kSectionHalfExtent = 1e9;

    explicit ClipPanel(QWidget* parent = nullptr);

    // The clip box the fields describe, none when clipping is off.
    std::optional<ClipBox> clip() const;
    // Where "Fit to cloud" puts the box (source coordinates), and where "Centre on picked
    // point" moves it.
    void setCloudBounds(const glm::dvec3& min, const glm::dvec3& max);
    void setPickedPoint(const glm::dvec3& point);

    void setEnabled(bool on);
    void setSection(bool section);
    void setCenter(const glm::dvec3& center);
    void setSize(const glm::dvec3& size); // a section's thickness is size.x
    void setYawDegrees(double degrees);

signals:
    void clipChanged(const std::optional<omicron::ClipBox>& clip);

private:
    void emitChanged();
    void updateModeFields();

    QCheckBox* m_enabled = nullptr;
    QComboBox* m_mode = nullptr;
    QDoubleSpinBox* m_center[3] = {};
    QDoubleSpinBox* m_size[3] = {};
    QDoubleSpinBox* m_yaw = nullptr;
    glm::dvec3 m_boundsMin{0.0}, m_boundsMax{1.0};
    std::optional<glm::dvec3> m_picked;
    bool m_updating = false;
};

} // namespace omicron
