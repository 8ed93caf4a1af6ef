#include "panels/generate_dialog.hpp"

#include "culling/core/errors.hpp"
#include "culling/scene/scene_io.hpp"

#include <QDialogButtonBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QSpinBox>

namespace lcui {

namespace {
QDoubleSpinBox* spin(double lo, double hi, double v, int decimals = 3) {
    auto* s = new QDoubleSpinBox;
    s->setRange(lo, hi);
    s->setDecimals(decimals);
    s->setValue(v);
    return s;
}
QWidget* triple(QDoubleSpinBox* (&s)[3], const glm::dvec3& v, double lo, double hi) {
    auto* w = new QWidget;
    auto* h = new QHBoxLayout(w);
    h->setContentsMargins(0, 0, 0, 0);
    for (int i = 0; i < 3; ++i) {
        s[i] = spin(lo, hi, v[i]);
        h->addWidget(s[i]);
    }
    return w;
}
} // namespace

GenerateLightsDialog::GenerateLightsDialog(const lc::LightGenSettings& g, QWidget* parent)
    : QDialog(parent) {
    setWindowTitle(tr("Generate lights"));
    auto* form = new QFormLayout(this);
    count_ = new QSpinBox;
    count_->setRange(1, 100000);
    count_->setValue(int(g.count));
    count_->setObjectName("genCount");
    form->addRow(tr("Count"), count_);
    seed_ = new QSpinBox;
    seed_->setRange(0, 2147483647);
    seed_->setValue(int(g.seed));
    seed_->setObjectName("genSeed");
    form->addRow(tr("Seed"), seed_);
    form->addRow(tr("Volume min"), triple(boxMin_, g.boxMin, -1e6, 1e6));
    form->addRow(tr("Volume max"), triple(boxMax_, g.boxMax, -1e6, 1e6));
    intensityMin_ = spin(0, 1e9, g.intensityMin);
    intensityMax_ = spin(0, 1e9, g.intensityMax);
    intensityMin_->setObjectName("genIntensityMin");
    intensityMax_->setObjectName("genIntensityMax");
    form->addRow(tr("Intensity min"), intensityMin_);
    form->addRow(tr("Intensity max"), intensityMax_);
    form->addRow(tr("Colour min"), triple(colorMin_, g.colorMin, 0, 100));
    form->addRow(tr("Colour max"), triple(colorMax_, g.colorMax, 0, 100));
    minIntensity_ = spin(1e-6, 1e9, g.minIntensity, 6);
    form->addRow(tr("Min intensity (I_min)"), minIntensity_);
    // Spots get a uniform direction and an outer angle uniform in this range
    // (lc::generateLights); the same bounds the scene model accepts.
    spotFraction_ = spin(0, 1, g.spotFraction, 2);
    spotFraction_->setSingleStep(0.1);
    spotFraction_->setObjectName("genSpotFraction");
    form->addRow(tr("Spot light fraction"), spotFraction_);
    spotAngleMin_ = spin(0.01, 90, g.spotAngleMinDeg, 2);
    spotAngleMin_->setObjectName("genSpotAngleMin");
    spotAngleMax_ = spin(0.01, 90, g.spotAngleMaxDeg, 2);
    spotAngleMax_->setObjectName("genSpotAngleMax");
    form->addRow(tr("Spot outer angle min (deg)"), spotAngleMin_);
    form->addRow(tr("Spot outer angle max (deg)"), spotAngleMax_);
    // An inverted angle range is refused at OK like the intensity's (below),
    // not put in order while the user types: a max typed digit by digit
    // ("6" of "60") dragged the min down with it.
    // Settings the generator refuses keep the dialog open with the reason,
    // every value as typed.
    error_ = new QLabel;
    error_->setObjectName("genError");
    error_->setStyleSheet("color: rgb(200,40,40)");
    error_->setWordWrap(true);
    error_->hide();
    form->addRow(error_);
    auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel);
    connect(buttons, &QDialogButtonBox::accepted, this, [this] {
        try {
            lc::checkLightGen(settings());
        } catch (const lc::Error& e) {
            error_->setText(QString::fromStdString(e.what()));
            error_->show();
            return;
        }
        accept();
    });
    connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
    form->addRow(buttons);
}

lc::LightGenSettings GenerateLightsDialog::settings() const {
    lc::LightGenSettings g;
    g.count = std::uint32_t(count_->value());
    g.seed = std::uint64_t(seed_->value());
    for (int i = 0; i < 3; ++i) {
        g.boxMin[i] = boxMin_[i]->value();
        g.boxMax[i] = boxMax_[i]->value();
        g.colorMin[i] = colorMin_[i]->value();
        g.colorMax[i] = colorMax_[i]->value();
    }
    g.intensityMin = intensityMin_->value();
    g.intensityMax = intensityMax_->value();
    g.minIntensity = minIntensity_->value();
    g.spotFraction = spotFraction_->value();
    g.spotAngleMinDeg = spotAngleMin_->value();
    g.spotAngleMaxDeg = spotAngleMax_->value();
    return g;
}

} // namespace lcui
