#include "window/param_toolbars.hpp"

#include "document/document.hpp"
#include "widgets/field_events.hpp"

#include "culling/core/errors.hpp"
#include "culling/core/params.hpp"
#include "culling/core/presets.hpp"

#include <QCheckBox>
#include <QComboBox>
#include <QLabel>
#include <QMainWindow>
#include <QSpinBox>
#include <QToolBar>

#include <algorithm>

namespace lcui {

ParamToolbars::ParamToolbars(QMainWindow* window, Document* doc) : QObject(window), doc_(doc) {
    cullBar_ = window->addToolBar(tr("Culling"));
    cullBar_->setObjectName("cullToolbar");
    // The engine limits on a row of their own, after the engine preset that
    // sets them (docs/ENGINES.md).
    window->addToolBarBreak();
    QToolBar* limitsBar = window->addToolBar(tr("Limits"));
    limitsBar->setObjectName("limitsToolbar");
    limitsBar->addWidget(new QLabel(tr("Engine preset ")));
    presetCombo_ = new QComboBox;
    presetCombo_->setObjectName("presetCombo");
    presetCombo_->addItem(tr("(none)"), QString());
    for (const lc::EnginePreset& p : lc::enginePresets())
        presetCombo_->addItem(QString::fromStdString(p.name), QString::fromStdString(p.name));
    presetCombo_->setToolTip(tr("Cull as a shipped engine does: its algorithm, grid and limits (docs/ENGINES.md). "
                                "Shows the preset the settings equal, (none) once one is changed."));
    for (int i = 1; i < presetCombo_->count(); ++i) {
        const lc::EnginePreset& p = lc::enginePreset(presetCombo_->itemData(i).toString().toStdString());
        presetCombo_->setItemData(i, QString::fromStdString(p.engine + ". Left out: " + p.leftOut), Qt::ToolTipRole);
    }
    connect(presetCombo_, qOverload<int>(&QComboBox::activated), this, [this](int i) {
        const std::string name = presetCombo_->itemData(i).toString().toStdString();
        if (!name.empty()) applyPreset(name);
    });
    limitsBar->addWidget(presetCombo_);
    limitsBar->addSeparator();
    // raster's proxy settings on a third row, shown only while the
    // algorithm is raster (on the first row they pushed the tile size out of
    // sight, on the second the limits).
    window->addToolBarBreak();
    rasterBar_ = window->addToolBar(tr("Raster proxies"));
    rasterBar_->setObjectName("rasterToolbar");
    rasterBar_->setVisible(false);
    addParamWidgets(limitsBar);
    // Ctrl+Z in a culling field undoes the scene's last edit (tile, width and
    // height are camera edits), as in the properties panel.
    (new UndoKeysToWindow(cullBar_))->watch(cullBar_);
}

// A control per parameter: a check box, a combo of the choices or a spin box,
// named "param_<name>", on the Limits row for the "limits" group, on the
// Raster proxies row for raster's proxy settings.
void ParamToolbars::addParamWidgets(QToolBar* limitsBar) {
    for (const lc::ParamSpec& p : lc::cullParams()) {
        const bool rasterParam = p.name.rfind("proxy-", 0) == 0 || p.name == "conservative";
        QToolBar* bar = rasterParam ? rasterBar_ : p.group == "limits" ? limitsBar : cullBar_;
        const std::string name = p.name;
        const QString tip = QString::fromStdString(p.help);
        const QString label = QString::fromStdString(p.label.empty() ? p.name : p.label);
        QWidget* w = nullptr;
        if (p.type == lc::ParamType::Bool) {
            auto* cb = new QCheckBox(label);
            connect(cb, &QCheckBox::toggled, this, [this, name](bool on) { onEdited(name, on ? "true" : "false"); });
            w = cb;
        } else {
            auto* l = new QLabel(label + " ");
            l->setToolTip(tip);
            bar->addWidget(l);
            if (p.type == lc::ParamType::Choice || p.type == lc::ParamType::Real) {
                auto* combo = new QComboBox;
                for (const auto& c : p.choices) combo->addItem(QString::fromStdString(c));
                if (p.type == lc::ParamType::Real) {
                    // A number typed in, or a common one picked: the word
                    // (auto), 1 (the mesh inscribed in the light) and steps up.
                    combo->setEditable(true);
                    combo->setInsertPolicy(QComboBox::NoInsert);
                    if (!p.realWord.empty()) combo->addItem(QString::fromStdString(p.realWord));
                    for (const char* v : {"1", "1.05", "1.1", "1.2", "1.3"}) combo->addItem(v);
                    combo->setMinimumContentsLength(5);
                }
                connect(combo, &QComboBox::textActivated, this,
                        [this, name](const QString& v) { onEdited(name, v.trimmed()); });
                w = combo;
            } else {
                auto* spin = new QSpinBox;
                spin->setRange(int(std::max<long long>(p.minValue, -2147483647)),
                               int(std::min<long long>(p.maxValue, 2147483647)));
                spin->setKeyboardTracking(false);
                connect(spin, qOverload<int>(&QSpinBox::valueChanged), this,
                        [this, name](int v) { onEdited(name, QString::number(v)); });
                w = spin;
            }
        }
        w->setToolTip(tip);
        w->setObjectName(QString::fromStdString("param_" + name));
        widgets_[name] = w;
        tips_[name] = tip;
        bar->addWidget(w);
    }
}

void ParamToolbars::sync() {
    syncing_ = true;
    rasterBar_->setVisible(doc_->runs().settings().algorithm == lc::Algorithm::Raster);
    for (auto& [name, w] : widgets_) {
        QString v;
        try {
            v = QString::fromStdString(lc::getParam(doc_->runs().settings(), doc_->scene().camera, name));
        } catch (const lc::Error&) {
            continue;
        }
        if (auto* cb = qobject_cast<QCheckBox*>(w)) cb->setChecked(v == "true" || v == "1");
        else if (auto* combo = qobject_cast<QComboBox*>(w)) combo->setCurrentText(v);
        else if (auto* spin = qobject_cast<QSpinBox*>(w)) spin->setValue(v.toInt());
    }
    const lc::EnginePreset* matching =
        lc::presetMatching(doc_->runs().settings(), doc_->scene().camera, doc_->scene().lights.size());
    presetCombo_->setCurrentIndex(matching ? presetCombo_->findData(QString::fromStdString(matching->name)) : 0);
    syncing_ = false;
}

void ParamToolbars::setListsFromShader(const QString& shader) {
    for (auto& [name, w] : widgets_) {
        if (name == "width" || name == "height" || name == "tile") continue;
        w->setEnabled(shader.isEmpty());
        w->setToolTip(shader.isEmpty() ? tips_[name]
                                       : tr("The custom shader %1 makes the lists: this setting is the built-in "
                                            "algorithms' (Culling > Built-in algorithm uses it again)")
                                             .arg(shader));
    }
    presetCombo_->setEnabled(shader.isEmpty());
}

void ParamToolbars::applyPreset(const std::string& name) {
    lc::CullSettings s;
    lc::Camera cam = doc_->scene().camera;
    try {
        lc::applyPreset(lc::enginePreset(name), s, cam, doc_->scene().lights.size());
    } catch (const lc::Error& e) {
        emit logged(QString::fromStdString(e.what()), true);
        sync();
        return;
    }
    const lc::EnginePreset& p = lc::enginePreset(name);
    emit logged(tr("preset %1: %2 (left out: %3)")
                    .arg(QString::fromStdString(name), QString::fromStdString(p.engine),
                         QString::fromStdString(p.leftOut)),
                false);
    doc_->runs().setSettings(s);
    if (cam.tileSize != doc_->scene().camera.tileSize)
        doc_->setCamera(cam, tr("Preset %1").arg(QString::fromStdString(name)));
    sync();
}

bool ParamToolbars::setPreset(const QString& name) {
    const int i = presetCombo_->findData(name);
    if (i < 1) return false;
    presetCombo_->setCurrentIndex(i);
    emit presetCombo_->activated(i); // what a user's pick emits
    return presetCombo_->currentIndex() == i;
}

void ParamToolbars::onEdited(const std::string& name, const QString& value) {
    if (syncing_) return;
    lc::CullSettings s = doc_->runs().settings();
    lc::Camera cam = doc_->scene().camera;
    try {
        lc::setParam(s, cam, name, value.toStdString());
    } catch (const lc::Error& e) {
        emit logged(QString::fromStdString(e.what()), true);
        sync();
        return;
    }
    const lc::Camera& old = doc_->scene().camera;
    if (cam.width != old.width || cam.height != old.height || cam.tileSize != old.tileSize)
        doc_->setCamera(cam, tr("Set %1").arg(QString::fromStdString(name)));
    else
        doc_->runs().setSettings(s);
}

bool ParamToolbars::setParam(const QString& name, const QString& value) {
    auto it = widgets_.find(name.toStdString());
    if (it == widgets_.end()) return false;
    QWidget* w = it->second;
    if (auto* cb = qobject_cast<QCheckBox*>(w)) {
        cb->setChecked(value == "true" || value == "1");
    } else if (auto* combo = qobject_cast<QComboBox*>(w)) {
        const int i = combo->findText(value);
        if (i < 0) return false;
        combo->setCurrentIndex(i);
        emit combo->textActivated(value); // what a user's pick emits
    } else if (auto* spin = qobject_cast<QSpinBox*>(w)) {
        spin->setValue(value.toInt());
    }
    return QString::fromStdString(lc::getParam(doc_->runs().settings(), doc_->scene().camera, name.toStdString())) ==
           value;
}

} // namespace lcui
