#include "clip_panel.hpp"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QGridLayout>
#include <QLabel>
#include <QHBoxLayout>
#include <QPushButton>
#include <QSignalBlocker>
#include <cmath>

namespace omicron {

namespace {

constexpr double kDegrees = 3.14159265358979323846 / 180.0;

QDoubleSpinBox* coordinateSpin(QWidget* parent, const QString& name) {
    auto* spin = new QDoubleSpinBox(parent);
    spin->setObjectName(name);
    spin->setDecimals(3);
    spin->setRange(-1e9, 1e9);
    spin->setSingleStep(1.0);
    spin->setKeyboardTracking(false); // a value once typed, not at every digit
    spin->setMinimumWidth(80);        // not as wide as its range's widest text
    return spin;
}

} // namespace

ClipPanel::ClipPanel(QWidget* parent) : QWidget(parent) {
    auto* form = new QFormLayout(this);
    m_enabled = new QCheckBox(tr("Draw only what lies inside"), this);
    m_enabled->setObjectName(QStringLiteral("clipEnabled"));
    m_enabled->setToolTip(tr("Clip the cloud to the box or section below: points outside are "
                             "not drawn (nor loaded or counted in the point budget), and File "
                             "→ Export Points… exports only the points inside"));
    form->addRow(tr("Clipping"), m_enabled);
    m_mode = new QComboBox(this);
    m_mode->setObjectName(QStringLiteral("clipMode"));
    m_mode->addItems({tr("box"), tr("section (slab)")});
    m_mode->setToolTip(tr("Box: centre, size and turn. Section: a slab through the centre, as "
                          "thick as the thickness, across the turned x axis (a vertical "
                          "section plane), unbounded along the plane"));
    form->addRow(tr("Mode"), m_mode);
    const char* axes[3] = {"X", "Y", "Z"};
    for (int axis = 0; axis < 3; ++axis) {
        m_center[axis] =
            coordinateSpin(this, QStringLiteral("clipCenter%1").arg(QLatin1String(axes[axis])));
        m_size[axis] =
            coordinateSpin(this, QStringLiteral("clipSize%1").arg(QLatin1String(axes[axis])));
        m_size[axis]->setRange(1e-3, 1e9);
    }
    // One row per axis, centre and size side by side: narrow enough for a side panel.
    auto* grid = new QGridLayout();
    grid->addWidget(new QLabel(tr("Centre"), this), 0, 1);
    grid->addWidget(new QLabel(tr("Size"), this), 0, 2);
    for (int axis = 0; axis < 3; ++axis) {
        grid->addWidget(new QLabel(QLatin1String(axes[axis]), this), axis + 1, 0);
        grid->addWidget(m_center[axis], axis + 1, 1);
        grid->addWidget(m_size[axis], axis + 1, 2);
    }
    form->addRow(grid);
    m_yaw = new QDoubleSpinBox(this);
    m_yaw->setObjectName(QStringLiteral("clipYaw"));
    m_yaw->setRange(-360.0, 360.0);
    m_yaw->setDecimals(1);
    m_yaw->setSuffix(QStringLiteral("°"));
    m_yaw->setKeyboardTracking(false);
    m_yaw->setToolTip(tr("Turn about the vertical axis, from +x towards +y"));
    form->addRow(tr("Turn"), m_yaw);
    auto* buttons = new QHBoxLayout();
    auto* fit = new QPushButton(tr("Fit to cloud"), this);
    fit->setObjectName(QStringLiteral("clipFit"));
    auto* picked = new QPushButton(tr("Centre on picked point"), this);
    picked->setObjectName(QStringLiteral("clipCenterPicked"));
    picked->setToolTip(tr("Move the centre to the last point hovered in the view"));
    buttons->addWidget(fit);
    buttons->addWidget(picked);
    form->addRow(buttons);

    connect(m_enabled, &QCheckBox::toggled, this, &ClipPanel::emitChanged);
    connect(m_mode, &QComboBox::currentIndexChanged, this, [this] {
        updateModeFields();
        emitChanged();
    });
    for (int axis = 0; axis < 3; ++axis) {
        connect(m_center[axis], &QDoubleSpinBox::valueChanged, this, &ClipPanel::emitChanged);
        connect(m_size[axis], &QDoubleSpinBox::valueChanged, this, &ClipPanel::emitChanged);
    }
    connect(m_yaw, &QDoubleSpinBox::valueChanged, this, &ClipPanel::emitChanged);
    connect(fit, &QPushButton::clicked, this, [this] {
        setCenter((m_boundsMin + m_boundsMax) * 0.5);
        setSize(glm::max(m_boundsMax - m_boundsMin, glm::dvec3(1e-3)));
    });
    connect(picked, &QPushButton::clicked, this, [this] {
        if (m_picked) {
            setCenter(*m_picked);
        }
    });
    updateModeFields();
}

std::optional<ClipBox> ClipPanel::clip() const {
    if (!m_enabled->isChecked()) {
        return std::nullopt;
    }
    ClipBox box;
    box.center = glm::dvec3(m_center[0]->value(), m_center[1]->value(), m_center[2]->value());
    box.yawRadians = m_yaw->value() * kDegrees;
    if (m_mode->currentIndex() == 1) {
        box.halfSize = glm::dvec3(m_size[0]->value() / 2.0, kSectionHalfExtent, kSectionHalfExtent);
    } else {
        box.halfSize =
            glm::dvec3(m_size[0]->value(), m_size[1]->value(), m_size[2]->value()) / 2.0;
    }
    return box;
}

void ClipPanel::setCloudBounds(const glm::dvec3& min, const glm::dvec3& max) {
    m_boundsMin = min;
    m_boundsMax = max;
    if (!m_enabled->isChecked()) { // a new cloud: the fields start around it
        setCenter((min + max) * 0.5);
        setSize(glm::max(max - min, glm::dvec3(1e-3)));
    }
}

void ClipPanel::setPickedPoint(const glm::dvec3& point) {
    m_picked = point;
}

void ClipPanel::setEnabled(bool on) {
    m_enabled->setChecked(on);
}

void ClipPanel::setSection(bool section) {
    m_mode->setCurrentIndex(section ? 1 : 0);
}

void ClipPanel::setCenter(const glm::dvec3& center) {
    m_updating = true;
    for (int axis = 0; axis < 3; ++axis) {
        m_center[axis]->setValue(center[axis]);
    }
    m_updating = false;
    emitChanged();
}

void ClipPanel::setSize(const glm::dvec3& size) {
    m_updating = true;
    for (int axis = 0; axis < 3; ++axis) {
        m_size[axis]->setValue(size[axis]);
    }
    m_updating = false;
    emitChanged();
}

void ClipPanel::setYawDegrees(double degrees) {
    m_yaw->setValue(degrees);
}

void ClipPanel::updateModeFields() {
    // A section has one size: its thickness (the first field).
    const bool section = m_mode->currentIndex() == 1;
    m_size[1]->setVisible(!section);
    m_size[2]->setVisible(!section);
    m_size[0]->setToolTip(section ? tr("Thickness of the section") : tr("Size along the turned x"));
}

void ClipPanel::emitChanged() {
    if (!m_updating) { // several fields set at once: one change
        emit clipChanged(clip());
    }
}

} // namespace omicron
