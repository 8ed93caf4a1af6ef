// The Report dock's queue: the parameter controls (which values a sweep
// takes), the configurations they queue per backend and the estimate of how
// long those take at the last sweep's pace.
#include "panels/report_dock.hpp"
#include "panels/report_text.hpp"

#include "document/document.hpp"

#include "culling/core/backend.hpp"

#include <QComboBox>
#include <QEvent>
#include <QLabel>
#include <QLocale>
#include <QMenu>
#include <QMouseEvent>
#include <QSettings>
#include <QSpinBox>
#include <QToolButton>

#include <algorithm>

namespace lcui {

namespace reporttext {

QString duration(double seconds) {
    if (seconds < 1) return ReportDock::tr("under a second");
    if (seconds < 90) return ReportDock::tr("%1 s").arg(qRound(seconds));
    const int minutes = qRound(seconds / 60);
    if (minutes < 90) return ReportDock::tr("%1 min").arg(minutes);
    return ReportDock::tr("%1 h %2 min").arg(minutes / 60).arg(minutes % 60);
}
QString aboutTime(double seconds) {
    return seconds < 1 ? duration(seconds) : ReportDock::tr("about %1").arg(duration(seconds));
}

QString count(std::size_t n) { return QLocale(QLocale::English).toString(qulonglong(n)); }

QString join(const std::vector<std::string>& values) {
    std::string s;
    for (const std::string& v : values) s += (s.empty() ? "" : ",") + v;
    return QString::fromStdString(s);
}

} // namespace reporttext

using namespace reporttext;

namespace {

// A held parameter's menu stays open while values are toggled.
class StayOpen : public QObject {
public:
    using QObject::QObject;
    bool eventFilter(QObject* o, QEvent* e) override {
        auto* menu = qobject_cast<QMenu*>(o);
        if (menu && e->type() == QEvent::MouseButtonRelease) {
            QAction* a = menu->actionAt(static_cast<QMouseEvent*>(e)->pos());
            if (a && a->isCheckable() && a->isEnabled()) {
                a->trigger();
                return true;
            }
        }
        return QObject::eventFilter(o, e);
    }
};

} // namespace

void ReportDock::addParamControl(const lc::ParamSpec& p, const std::vector<std::string>& values,
                                 const std::vector<std::string>& checked) {
    auto c = std::make_unique<ParamControl>();
    c->name = p.name;
    c->values = values;
    c->button = new QToolButton;
    c->button->setObjectName(QString::fromStdString("reportParam_" + p.name));
    c->button->setPopupMode(QToolButton::InstantPopup);
    c->menu = new QMenu(c->button);
    c->menu->installEventFilter(new StayOpen(c->menu));
    QAction* every = c->menu->addAction(tr("Every value"));
    every->setObjectName("every");
    c->menu->addSeparator();
    for (const std::string& v : values) {
        QAction* a = c->menu->addAction(QString::fromStdString(v));
        a->setCheckable(true);
        a->setData(QString::fromStdString(v));
        a->setChecked(std::find(checked.begin(), checked.end(), v) != checked.end());
    }
    c->button->setMenu(c->menu);
    ParamControl* raw = c.get();
    connect(c->menu, &QMenu::triggered, this, [this, raw](QAction* a) { paramToggled(*raw, a); });
    params_.push_back(std::move(c));
    paramToggled(*raw, nullptr);
}

void ReportDock::paramToggled(ParamControl& c, QAction* changed) {
    std::vector<QAction*> values;
    for (QAction* a : c.menu->actions())
        if (a->isCheckable()) values.push_back(a);
    if (changed && !changed->isCheckable()) // Every value
        for (QAction* a : values) a->setChecked(true);
    // A parameter holds at least one value: the last one stays checked.
    if (std::none_of(values.begin(), values.end(), [](QAction* a) { return a->isChecked(); }) && changed)
        changed->setChecked(true);
    QStringList on;
    for (QAction* a : values)
        if (a->isChecked()) on << a->data().toString();
    const QString label = QString::fromStdString(lc::cullParam(c.name).label);
    QString text;
    if (c.name == "tile" || c.name == "cells" || (on.size() <= 2 && on.size() < int(values.size())))
        text = on.join(",");
    else if (on.size() == int(values.size()))
        text = tr("every (%1)").arg(on.size());
    else
        text = tr("%1 of %2").arg(on.size()).arg(values.size());
    c.button->setText(tr("%1: %2").arg(label, text));
    c.button->setToolTip(tr("%1 swept over: %2").arg(label, on.join(", ")));
    if (queue_) updateQueueLabel();
}

lc::ReportOptions ReportDock::optionsFromControls() const {
    lc::ReportOptions o = options_;
    o.backends.clear();
    if (const QString b = backendBox_->currentData().toString(); !b.isEmpty()) o.backends = {b.toStdString()};
    o.repeat = repeatBox_->value();
    for (const auto& c : params_) {
        std::vector<std::string> on;
        for (QAction* a : c->menu->actions())
            if (a->isCheckable() && a->isChecked()) on.push_back(a->data().toString().toStdString());
        if (c->name == "tile" || c->name == "cells") {
            std::vector<std::uint32_t>& list = c->name == "tile" ? o.tileSizes : o.cellCounts;
            list.clear();
            for (const std::string& v : on) list.push_back(std::uint32_t(std::stoul(v)));
            o.fixed.erase(c->name);
        } else if (on.size() == c->values.size()) {
            o.fixed.erase(c->name); // swept over all its values
        } else {
            o.fixed[c->name] = join(on).toStdString();
        }
    }
    return o;
}

// The backend box lists the backends found when the dock was made (finding
// them opens a Vulkan instance: tens of milliseconds on lavapipe, which the
// queue label paid at every step of a Live drag).
std::vector<std::string> ReportDock::sweptBackends() const {
    if (const QString b = backendBox_->currentData().toString(); !b.isEmpty()) return {b.toStdString()};
    std::vector<std::string> all;
    for (int i = 0; i < backendBox_->count(); ++i)
        if (const QString b = backendBox_->itemData(i).toString(); !b.isEmpty()) all.push_back(b.toStdString());
    return all;
}

std::map<std::string, std::size_t> ReportDock::queuedPerBackend() const {
    const lc::ReportOptions o = optionsFromControls();
    const bool spots = doc_->scene().hasSpotLights();
    const std::vector<std::string> backends = sweptBackends();
    // What the count depends on: the swept values, the backends and whether
    // the scene has spot lights, not where its lights are. Worked out again
    // only when one of those changes (every light edit updates the label).
    std::string key = spots ? "spots" : "points";
    for (const std::string& b : backends) key += "|" + b;
    key += "|tiles";
    for (std::uint32_t t : o.tileSizes) key += " " + std::to_string(t);
    key += "|cells";
    for (std::uint32_t c : o.cellCounts) key += " " + std::to_string(c);
    for (const auto& [name, value] : o.fixed) key += "|" + name + "=" + value;
    if (key == queuedKey_) return queued_;
    std::map<std::string, std::size_t> n;
    for (const std::string& b : backends) n[b] = lc::reportConfigs(o, b, spots).size();
    queuedKey_ = key;
    queued_ = n;
    return n;
}

std::size_t ReportDock::queuedConfigurations() const {
    std::size_t total = 0;
    for (const auto& [b, k] : queuedPerBackend()) total += k;
    return total;
}

std::optional<double> ReportDock::estimatedSeconds() const {
    if (pace_.empty() || paceKey_ != paceKey()) return std::nullopt;
    double seconds = 0;
    for (const auto& [b, k] : queuedPerBackend()) {
        auto it = pace_.find(b);
        if (it == pace_.end()) return std::nullopt;
        seconds += double(k) * it->second;
    }
    return seconds;
}

QString ReportDock::paceKey() const {
    const lc::Scene& s = doc_->scene();
    return QString("%1|%2x%3|%4 lights|geometry %5|repeat %6 warmup %7")
        .arg(QString::fromStdString(s.name))
        .arg(s.camera.width)
        .arg(s.camera.height)
        .arg(s.lights.size())
        .arg(doc_->geometryRevision())
        .arg(repeatBox_->value())
        .arg(options_.warmup);
}

void ReportDock::updateQueueLabel() {
    // spot-* parameters are swept only for a scene with spot lights.
    const bool spots = doc_->scene().hasSpotLights();
    for (const auto& c : params_)
        if (c->name.rfind("spot-", 0) == 0) {
            c->button->setEnabled(spots);
            if (!spots) c->button->setToolTip(tr("The scene has no spot light: not swept."));
        }
    std::size_t n = 0;
    try {
        n = queuedConfigurations();
    } catch (const std::exception& e) {
        queue_->setText(tr("Cannot queue the sweep: %1").arg(QString::fromStdString(e.what())));
        return;
    }
    QString text = n == 1 ? tr("Queues 1 configuration") : tr("Queues %1 configurations").arg(count(n));
    if (const std::optional<double> s = estimatedSeconds()) {
        double perConfig = 0;
        for (const auto& [b, pace] : pace_) perConfig = std::max(perConfig, pace);
        text += tr(": %1 (an estimate from the last run on this scene, up to %2 s a configuration).")
                    .arg(aboutTime(*s))
                    .arg(perConfig, 0, 'g', 2);
    } else {
        text += tr("; the time is not known yet: Run times the first configuration and asks before going on "
                   "when the whole sweep would take over %1.")
                    .arg(duration(confirmAboveSeconds));
    }
    queue_->setText(text);
}

} // namespace lcui
