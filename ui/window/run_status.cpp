#include "window/run_status.hpp"

#include "document/document.hpp"
#include "widgets/count_text.hpp"
#include "widgets/message_log.hpp"

#include "culling/capture/capture_frame.hpp"
#include "culling/custom/custom_cull.hpp"
#include "culling/scene/gltf_io.hpp"

#include <QFileInfo>
#include <QLabel>
#include <QStatusBar>
#include <QStringList>

#include <algorithm>

namespace lcui {

namespace {

// How a run's all-lights image was made, when not shaded from every light.
QString allLightsNote(const lc::RunOutput& out) {
    if (out.allLightsReused) return RunStatus::tr(" (the all-lights image kept: same pixels and lights)");
    if (!out.allLightsUpdate) return {};
    const auto& u = *out.allLightsUpdate;
    return RunStatus::tr(" (the all-lights image updated for the lights that changed: terms out %1, in %2; "
                         "pixels shaded again from every light %3)")
        .arg(qulonglong(u.removed))
        .arg(qulonglong(u.added))
        .arg(qulonglong(u.pixelsShadedAgain));
}

// The lists' time; a capture's lists were made by the renderer, untimed here.
QString cullTime(const lc::RunOutput& out) {
    if (out.result.timings.cullMs < 0) return RunStatus::tr("untimed (the renderer's lists)");
    return RunStatus::tr("%1 ms").arg(out.result.timings.cullMs, 0, 'f', 2);
}

// Whose lists a run judged: the built-in algorithm's name, a custom shader's
// or a RenderDoc capture's (its depth came from the capture).
QString listSourceName(const lc::RunOutput& out, bool longForm) {
    if (!out.custom) return QString(lc::toString(out.result.algorithm));
    if (lc::captureDepth(out)) return longForm ? RunStatus::tr("lists of capture") : "capture";
    return longForm ? RunStatus::tr("custom shader") : "custom";
}

const char* const kStaleStyle = "color: white; background: #b9770e; padding: 0 4px";

} // namespace

RunStatus::RunStatus(Document* doc, MessageLog* log, QStatusBar* bar, QObject* parent)
    : QObject(parent), doc_(doc), log_(log), bar_(bar) {
    auto label = [bar](const char* name) {
        auto* l = new QLabel;
        l->setObjectName(name);
        bar->addPermanentWidget(l);
        return l;
    };
    backend_ = label("statusBackend");
    times_ = label("statusTimes");
    fn_ = label("statusFalseNegatives");
    efficiency_ = label("statusEfficiency");
    lists_ = label("statusLists");
    cutoff_ = label("statusCutoff");
    connect(&doc_->runs(), &RunState::runOutputChanged, this, &RunStatus::update);
    connect(&doc_->runs(), &RunState::runWentStale, this, &RunStatus::update);
    // The cut-off label follows the scene (a new file, an undone cut-off).
    connect(doc_, &Document::sceneReset, this, &RunStatus::updateCutoff);
    connect(doc_, &Document::lightsChanged, this, &RunStatus::updateCutoff);
    update();
    updateCutoff();
}

void RunStatus::backendReady(const QString& name, const QString& device) {
    lastBackendName_ = name;
    lastDeviceName_ = device;
    log_->log(tr("backend %1 on %2").arg(name, device));
    update();
}

void RunStatus::finished(quint64 generation, const lc::RunOutput& out) {
    const auto& m = out.truth.metrics;
    // A Live edit's lists arrive before its ground truth: log once, with it;
    // the shaded images come last, with the image error.
    if (!out.shadedAll.empty()) {
        log_->log(tr("run %1: image RMSE %2, max error %3, shading %4 ms%5")
                      .arg(generation)
                      .arg(m.imageRmse, 0, 'g', 6)
                      .arg(m.imageMaxError, 0, 'g', 6)
                      .arg(out.result.timings.shadeMs, 0, 'f', 2)
                      .arg(allLightsNote(out)));
        return;
    }
    if (out.custom && out.truthComputed) logCustom(out);
    // The pre-pass's triangles, where it ran (the Vulkan backend draws only
    // the faces of closed solids turned towards the camera).
    const QString depthTriangles = out.result.depthTriangles == 0
                                       ? QString()
                                       : tr(" (%1 of %2 triangles)")
                                             .arg(qulonglong(out.result.depthTrianglesDrawn))
                                             .arg(qulonglong(out.result.depthTriangles));
    // The worker keeps the last depth image while the camera and meshes stay.
    const QString depthTime = lc::captureDepth(out) ? tr("from the capture")
                              : out.depthReused ? tr("reused (camera and meshes unchanged)")
                                                : tr("%1 ms").arg(out.result.timings.depthMs, 0, 'f', 2);
    if (out.truthComputed) {
        const QString line = tr("run %1: %2, %3, depth %4%8, cull %5, false negatives %6, efficiency %7")
                                 .arg(generation)
                                 .arg(listSourceName(out, false))
                                 .arg(countOf(out.lights.size(), "light", "lights"))
                                 .arg(depthTime)
                                 .arg(cullTime(out))
                                 .arg(m.falseNegatives)
                                 .arg(m.efficiency, 0, 'f', 4)
                                 .arg(depthTriangles);
        if (m.falseNegatives > 0) log_->warn(line); // a finding about the culling, not a failure of the run
        else log_->log(line);
        logLimits(generation, out);
    }
    bar_->showMessage(tr("culling done (run %1)").arg(generation), 4000);
}

void RunStatus::logCustom(const lc::RunOutput& out) {
    const lc::CustomCullReport& c = *out.custom;
    log_->log(tr("%9 %1 (%2, %3): overflowed lists %4, invalid indices %5, duplicate indices %10, validation "
                 "messages %6, %7 from built-in %8")
                  .arg(QString::fromStdString(c.source), QString::fromStdString(c.layout),
                       QString::fromStdString(c.lists))
                  .arg(c.overflowLists)
                  .arg(c.invalidIndices)
                  .arg(c.validationMessages.size())
                  .arg(countOf(c.listsDifferingFromBuiltin, "list differs", "lists differ"))
                  .arg(QString::fromStdString(c.builtinAlgorithm), listSourceName(out, true))
                  .arg(c.duplicateIndices),
              c.overflowLists > 0 || c.invalidIndices > 0 || c.duplicateIndices > 0 || !c.validationMessages.empty());
    for (const std::string& m : c.validationMessages) log_->log(QString::fromStdString(m), true);
}

// The engine limits: what they took, by cause, and what would keep it.
void RunStatus::logLimits(quint64 generation, const lc::RunOutput& out) {
    const auto& m = out.truth.metrics;
    const lc::ListLimits& lim = out.result.limits;
    if (out.custom || !out.result.settings.hasLimits() || (lim.empty() && !m.falseNegatives)) return;
    QString keep;
    if (m.falseNegativesListFull) keep += tr("; a cap of %1 (the longest list) never overflows").arg(lim.longestUncapped);
    if (m.falseNegativesLightLimit)
        keep += tr("; %1 past max-lights %2")
                    .arg(countOf(lim.lightsOverLimit, "light", "lights"))
                    .arg(out.result.settings.maxLights);
    log_->log(tr("run %1 limits: %2 over-full, %3 dropped; misses by cause: culling test %4, list "
                 "full %5, light limit %6%7 (lightcull report --presets finds the smallest values that keep every "
                 "light)")
                  .arg(generation)
                  .arg(countOf(lim.overflowLists.size(), "list", "lists"))
                  .arg(countOf(lim.droppedLights.size(), "entry", "entries"))
                  .arg(qulonglong(m.falseNegativesCullingTest()))
                  .arg(qulonglong(m.falseNegativesListFull))
                  .arg(qulonglong(m.falseNegativesLightLimit))
                  .arg(keep));
}

void RunStatus::failed(quint64 generation, const QString& message) {
    failedGeneration_ = std::max(failedGeneration_, generation);
    log_->log(tr("run %1 failed: %2").arg(generation).arg(message), true);
    bar_->showMessage(tr("culling failed: %1").arg(message), 10000);
    update();
}

void RunStatus::setShaderRefused(const QString& file, const QString& why) {
    refusedFile_ = why.isEmpty() ? QString() : file;
    refusedWhy_ = why;
    if (!why.isEmpty()) bar_->showMessage(tr("%1 refused: %2").arg(file, why), 10000);
    update();
}

void RunStatus::updateCutoff() {
    // The cut-off that sized the lights without a range: a radius the file
    // did not give, so the user should see where it came from.
    const std::size_t cut = lc::gltfCutoffLights(doc_->scene()).size();
    cutoff_->setVisible(cut > 0);
    cutoff_->setText(
        tr("cut-off %1 lux (%2)").arg(doc_->scene().origin.gltfMinIntensity).arg(countOf(cut, "light", "lights")));
    cutoff_->setToolTip(tr("%1 without a glTF range: their radius is sqrt(intensity x colour / I_min) "
                           "at I_min = %2 lux. File > glTF light cut-off... changes it.")
                            .arg(countOf(cut, "light", "lights"))
                            .arg(doc_->scene().origin.gltfMinIntensity));
}

void RunStatus::update() {
    const auto run = doc_->runs().runOutput();
    const QString backend = run ? QString::fromStdString(run->result.backend) : lastBackendName_;
    const QString device = run ? QString::fromStdString(run->result.device) : lastDeviceName_;
    backend_->setText(backend.isEmpty() ? tr("no backend yet") : tr("%1 | %2").arg(backend, device));
    if (!run) {
        times_->setText(tr("depth - ms | cull - ms"));
        fn_->setText(tr("FN -"));
        fn_->setStyleSheet({});
        efficiency_->setText(tr("efficiency -"));
        lists_->setText(tr("mean/max list -"));
        return;
    }
    // A run that only moved lights reuses the previous depth image (cull_worker).
    const QString depth = lc::captureDepth(*run) ? tr("depth from the capture")
                          : run->depthReused ? tr("depth reused")
                                             : tr("depth %1 ms").arg(run->result.timings.depthMs, 0, 'f', 2);
    times_->setText(tr("%1 | cull %2").arg(depth, cullTime(*run)));
    // The figures stay (they describe the run shown) but say they are old.
    const bool stale = doc_->runs().runIsStale();
    times_->setStyleSheet(stale ? kStaleStyle : "");
    times_->setToolTip(stale ? tr("The scene changed since this run: F5 runs it again.") : QString());
    if (stale) times_->setText(tr("stale: %1").arg(times_->text()));
    // A failed run (a custom shader that does not compile, settings the
    // device refuses), or a shader saved with settings it cannot use, leaves
    // the last good run on screen: say whose it is.
    QString instead, why;
    if (failedGeneration_ > doc_->runs().runGeneration()) {
        instead = tr("run %1 failed").arg(failedGeneration_);
        why = tr("The last run failed (the message log says why): the view, the tile inspector and these figures "
                 "are an earlier run's.");
    } else if (!refusedWhy_.isEmpty()) {
        instead = tr("%1 refused").arg(QFileInfo(refusedFile_).fileName());
        why = tr("The shader was saved with settings that cannot be used (%1): nothing was culled with it; the "
                 "view, the tile inspector and these figures are its earlier version's.")
                  .arg(refusedWhy_);
    }
    if (!instead.isEmpty()) {
        times_->setStyleSheet(kStaleStyle);
        times_->setText(tr("%1, showing run %2 (%3): %4")
                            .arg(instead, QString::number(doc_->runs().runGeneration()),
                                 listSourceName(*run, true), times_->text()));
        times_->setToolTip(why);
    }
    updateFigures(*run);
}

void RunStatus::updateFigures(const lc::RunOutput& run) {
    if (!run.truthComputed) {
        // Live edit: ground truth is still being computed (or was superseded).
        const auto& counts = run.result.listCount;
        std::uint64_t sum = 0, mx = 0;
        for (std::uint32_t c : counts) {
            sum += c;
            mx = std::max<std::uint64_t>(mx, c);
        }
        fn_->setText(tr("FN ..."));
        fn_->setStyleSheet("color: gray");
        efficiency_->setText(tr("efficiency ..."));
        lists_->setText(tr("mean/max list %1 / %2")
                            .arg(counts.empty() ? 0.0 : double(sum) / double(counts.size()), 0, 'f', 2)
                            .arg(mx));
        return;
    }
    const auto& m = run.truth.metrics;
    fn_->setText(m.falseNegatives > 0 ? tr("MISSES LIGHTS: FN %1").arg(m.falseNegatives)
                                      : tr("FN %1").arg(m.falseNegatives));
    // By cause, where the engine limits took some of them.
    if (m.falseNegativesListFull || m.falseNegativesLightLimit)
        fn_->setText(fn_->text() + tr(" (test %1, list full %2, light limit %3)")
                                       .arg(qulonglong(m.falseNegativesCullingTest()))
                                       .arg(qulonglong(m.falseNegativesListFull))
                                       .arg(qulonglong(m.falseNegativesLightLimit)));
    fn_->setStyleSheet(m.falseNegatives > 0 ? "color: white; background: #c0392b; padding: 0 4px" : "color: #2e7d32");
    // A custom shader's lists that hold a light twice or an index past the
    // light count lose no light but fail `lightcull run` (exit 3): said here.
    if (run.custom && (run.custom->duplicateIndices || run.custom->invalidIndices)) {
        QStringList flaws;
        if (const auto n = run.custom->invalidIndices)
            flaws << tr("%1 invalid %2").arg(n).arg(n == 1 ? "index" : "indices");
        if (const auto n = run.custom->duplicateIndices)
            flaws << tr("%1 duplicate %2").arg(n).arg(n == 1 ? "index" : "indices");
        fn_->setText(fn_->text() + " · " + flaws.join(", "));
        if (m.falseNegatives == 0) fn_->setStyleSheet("color: white; background: #d35400; padding: 0 4px");
    }
    // With misses efficiency is no score: lists that drop needed lights look
    // tighter than any correct list can be.
    if (m.falseNegatives > 0)
        efficiency_->setText(tr("efficiency %1: not a score with false negatives").arg(m.efficiency, 0, 'f', 4));
    else
        efficiency_->setText(tr("efficiency %1 (%2% of this grid's optimum)")
                                 .arg(m.efficiency, 0, 'f', 4)
                                 .arg(100.0 * m.efficiencyVsOptimal, 0, 'f', 1));
    efficiency_->setToolTip(tr("Exact work / shading work. The optimum is the shading work of lists holding "
                               "exactly the lights their pixels need together (optimal work %1): no culling "
                               "with these tiles, cells or froxels can do better.")
                                .arg(m.optimalWork));
    lists_->setText(tr("mean/max list %1 / %2").arg(m.meanList, 0, 'f', 2).arg(m.maxList));
}

} // namespace lcui
