#include "window/light_placement.hpp"

#include "document/document.hpp"
#include "views/inspector_view.hpp"
#include "widgets/count_text.hpp"
#include "widgets/message_log.hpp"
#include "window/prompts.hpp"
#include "work/progress_task.hpp"

#include "culling/core/errors.hpp"
#include "culling/scene/scene_io.hpp"

#include <set>

namespace lcui {

namespace {

// The generator numbers from light_0; beside the scene's lights the numbering
// goes on past theirs, so names (explain --light NAME, the scene tree's
// filter) stay unique.
void nameUniquely(const std::vector<lc::PointLight>& existing, std::vector<lc::PointLight>& added) {
    std::set<std::string> taken;
    for (const lc::PointLight& l : existing) taken.insert(l.name);
    std::size_t next = existing.size();
    for (lc::PointLight& l : added) {
        if (!taken.count(l.name)) {
            taken.insert(l.name);
            continue;
        }
        while (taken.count("light_" + std::to_string(next))) ++next;
        l.name = "light_" + std::to_string(next++);
        taken.insert(l.name);
    }
}

} // namespace

LightPlacement::LightPlacement(Document* doc, InspectorView* inspector, StatusProgress* progress, MessageLog* log,
                               const Prompts& prompts, QWidget* window)
    : QObject(window), doc_(doc), inspector_(inspector), progress_(progress), log_(log), prompts_(prompts),
      window_(window) {}

int LightPlacement::addAt(const QPoint& pos, lc::LightKind kind) {
    const lc::Scene& s = doc_->scene();
    const auto [lo, hi] = s.bounds();
    double diag = glm::length(hi - lo);
    if (diag <= 0) diag = std::max(1.0, glm::length(s.camera.target - s.camera.position));
    glm::dvec3 p = diag > 0 && s.triangleCount() > 0 ? 0.5 * (lo + hi) : s.camera.target;
    glm::dvec3 hit, normal(0.0, 1.0, 0.0);
    const bool onSurface = inspector_->rect().contains(pos) && inspector_->pickSurface(pos, &hit, &normal);
    lc::PointLight l;
    l.kind = kind;
    // A spot light stands off the surface by a tenth of the scene and points
    // back at it (no surface: above the centre, pointing down).
    const double standOff = kind == lc::LightKind::Spot ? 0.1 * diag : 0.01 * diag;
    if (onSurface) p = hit + normal * standOff; // off the surface, on the viewer's side
    else if (kind == lc::LightKind::Spot) p += normal * standOff;
    l.direction = -normal;
    l.outerAngleDeg = 30;
    l.name = QStringLiteral("%1 %2").arg(kind == lc::LightKind::Spot ? "spot" : "light").arg(s.lights.size()).toStdString();
    l.position = p;
    l.color = {1, 1, 1};
    l.minIntensity = 0.05;
    // Radius a tenth of the scene (a spot's range a fifth): r^2 = I / I_min.
    const double r = (kind == lc::LightKind::Spot ? 0.2 : 0.1) * diag;
    l.intensity = r * r * l.minIntensity;
    doc_->addLights({l}, kind == lc::LightKind::Spot ? tr("Add spot light") : tr("Add light"));
    return int(doc_->scene().lights.size()) - 1;
}

bool LightPlacement::generate(const lc::LightGenSettings& g) {
    std::vector<lc::PointLight> lights;
    try {
        lights = runWithProgressResult<std::vector<lc::PointLight>>(
            progress_, tr("Generating %1 lights...").arg(g.count),
            [g](const lc::CancelToken& c, const lc::Progress& p) { return lc::generateLights(g, &c, p); });
    } catch (const lc::Cancelled&) {
        log_->log(tr("light generation cancelled"));
        return false;
    } catch (const std::exception& e) {
        log_->log(tr("cannot generate lights: %1").arg(QString::fromStdString(e.what())), true);
        prompts_.showError(window_, tr("Generate lights"), QString::fromStdString(e.what()));
        return false;
    }
    nameUniquely(doc_->scene().lights, lights);
    doc_->addLights(lights, tr("Generate %1").arg(countOf(lights.size(), "light", "lights")), /*select=*/false);
    log_->log(tr("generated %1 (seed %2)").arg(countOf(lights.size(), "light", "lights")).arg(g.seed));
    return true;
}

} // namespace lcui
