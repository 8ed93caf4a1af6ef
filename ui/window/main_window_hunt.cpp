// Culling > Hunt for a miss... (issue 35): the library's hunt
// (culling/diagnostics/hunt.hpp) run on the window's culling, in the
// background with the status bar's progress and Cancel; the repro it writes
// opens as the scene, its miss selected and explained.
#include "window/main_window.hpp"
#include "work/custom_shader_source.hpp"

#include "document/document.hpp"
#include "panels/hunt_dialog.hpp"
#include "document/miss_navigator.hpp"
#include "work/cull_worker.hpp"
#include "work/progress_task.hpp"

#include "culling/core/errors.hpp"
#include "culling/diagnostics/hunt.hpp"

#include <QDir>
#include <QSettings>
#include <QStatusBar>

#include <algorithm>
#include <mutex>
#include <optional>

namespace lcui {

namespace {

// The culling under test in words, as the dialog shows it.
QString underTestText(const lc::CullSettings& s, const lc::CustomShaderOptions* shader, const QString& backend) {
    if (shader)
        return MainWindow::tr("custom shader %1 (layout %2, lists %3), depth pre-pass on %4")
            .arg(QString::fromStdString(shader->path), QString::fromStdString(lc::toString(shader->layout)),
                 QString::fromStdString(lc::toString(shader->lists)), backend);
    QStringList parts;
    lc::Camera scratch;
    for (const lc::ParamSpec& p : lc::cullParams())
        if (p.name != "width" && p.name != "height" && p.name != "tile")
            parts << QString::fromStdString(p.name + " " + lc::getParam(s, scratch, p.name));
    return MainWindow::tr("built-in %1 on %2").arg(parts.join(", "), backend);
}

} // namespace

void MainWindow::huntFromDialog() {
    if (captureLists_) {
        const QString why = tr("the run judges a RenderDoc capture's lists, which a hunt cannot vary: choose Culling > "
                               "Built-in algorithm or Custom shader... first");
        log(tr("Hunt: %1").arg(why), true);
        prompts.showError(this, tr("Hunt for a miss"), why);
        return;
    }
    QSettings st;
    HuntRequest initial;
    initial.folder = st.value("hunt/folder", QDir::home().filePath("lightcull-hunt")).toString();
    initial.seed = st.value("hunt/seed", 1).toULongLong();
    initial.trials = st.value("hunt/trials", 200).toULongLong();
    initial.seconds = st.value("hunt/seconds", 60.0).toDouble();
    initial.vary = st.value("hunt/vary", lc::HuntAll).toUInt() & lc::HuntAll;
    if (initial.vary == 0) initial.vary = lc::HuntAll;
    initial.openScene = st.value("hunt/openScene", true).toBool();
    HuntDialog dlg(initial, underTestText(doc_->runs().settings(), customShader_->options().get(), doc_->runs().backend()),
                   !doc_->scene().meshes.empty(), customShader_->options() != nullptr, this);
    if (dlg.exec() != QDialog::Accepted) return;
    const HuntRequest r = dlg.request();
    st.setValue("hunt/folder", r.folder);
    st.setValue("hunt/seed", qulonglong(r.seed));
    st.setValue("hunt/trials", qulonglong(r.trials));
    st.setValue("hunt/seconds", r.seconds);
    st.setValue("hunt/vary", r.vary);
    st.setValue("hunt/openScene", r.openScene);
    hunt(r);
}

bool MainWindow::hunt(const HuntRequest& r) {
    const std::string folder = r.folder.toStdString();
    if (const std::string why = lc::huntOutputProblem(folder); !why.empty()) {
        prompts.showError(this, tr("Hunt for a miss"), tr("Repro folder: %1").arg(QString::fromStdString(why)));
        return false;
    }
    lc::HuntOptions o;
    o.settings = doc_->runs().settings();
    if (const auto shader = customShader_->options()) o.shader = *shader;
    o.seed = r.seed;
    o.maxTrials = r.trials;
    o.maxSeconds = r.seconds;
    o.vary = r.vary;
    o.overflowIsFailure = r.overflow;
    const lc::Scene base = doc_->scene();
    if (r.openScene && !base.meshes.empty()) {
        o.baseScene = &base;
        o.vary &= ~unsigned(lc::HuntSceneDim); // the open scene's meshes stay
    }
    const std::string backendName = doc_->runs().backend().toStdString();
    const std::string device = doc_->runs().device().toStdString();

    std::mutex mutex; // guards `label` (the hunt's thread writes, the status bar reads)
    QString label = tr("hunting...");
    std::optional<lc::HuntResult> result;
    std::string command;
    log(tr("hunt: seed %1, %2 trials, %3 s, varying %4")
            .arg(r.seed)
            .arg(r.trials ? QString::number(r.trials) : tr("unlimited"))
            .arg(r.seconds > 0 ? QString::number(r.seconds) : tr("unlimited"))
            .arg(QString::fromStdString(lc::huntDimsToString(r.vary))));
    try {
        // On the culling worker's thread and backend (one device), as a job
        // that serves culling requests between its trials.
        runJobWithProgress(
            statusProgress_, service_, label,
            [&](CullJobContext& job, const lc::CancelToken& cancel, const lc::Progress& progress) {
                lc::HuntOptions opt = o;
                opt.cancel = &cancel;
                opt.progress = [&](const lc::HuntCoverage& c, double seconds) {
                    double f = 0;
                    if (opt.maxTrials) f = std::max(f, double(c.trials) / double(opt.maxTrials));
                    if (opt.maxSeconds > 0) f = std::max(f, seconds / opt.maxSeconds);
                    progress(std::min(1.0, f));
                    {
                        std::lock_guard<std::mutex> lock(mutex);
                        label = tr("hunt: %1 trials, %2/s; %3 orthographic, %4 reversed-Z, %5 wide spots")
                                    .arg(c.trials)
                                    .arg(seconds > 0 ? double(c.trials) / seconds : 0.0, 0, 'f', 1)
                                    .arg(c.orthographic)
                                    .arg(c.reversedZ)
                                    .arg(c.wideSpots);
                    }
                    job.serve();
                };
                lc::CullBackend& backend = job.backend(backendName);
                lc::HuntResult found = lc::hunt(opt, backend);
                command = lc::writeHuntRepro(found, opt, backend, folder, device);
                result = std::move(found);
            },
            [&] {
                std::lock_guard<std::mutex> lock(mutex);
                return label;
            });
    } catch (const lc::Cancelled&) {
        // The hunt stops at the next trial: what it covered still counts.
        if (!result) {
            log(tr("hunt cancelled"));
            return false;
        }
    } catch (const std::exception& e) {
        log(tr("hunt failed: %1").arg(QString::fromUtf8(e.what())), true);
        prompts.showError(this, tr("Hunt for a miss"), QString::fromUtf8(e.what()));
        return false;
    }

    if (!result->failure) {
        const QString text = QString::fromStdString(lc::huntNoMissText(*result, o)).trimmed();
        log(tr("hunt: %1; verdict in %2").arg(text, r.folder));
        statusBar()->showMessage(tr("Hunt: no miss in %1 trials").arg(result->coverage.trials), 8000);
        return false;
    }
    const lc::HuntFailure& f = *result->failure;
    log(tr("hunt: COUNTEREXAMPLE after %1 trials (%2 s): %3")
            .arg(f.trial + 1)
            .arg(result->seconds, 0, 'f', 1)
            .arg(QString::fromStdString(lc::huntVerdictText(f, o)).trimmed()),
        true);
    log(tr("hunt: repro in %1 (%2)").arg(r.folder, QString::fromStdString(command)));
    // The repro as the scene: its run selects the miss (the verdict's: the
    // culling test's misses first, most pixels first) and Explain shows it.
    const QString scene = QDir(r.folder).filePath("scene.json");
    if (!openSceneFile(scene)) {
        log(tr("the repro scene %1 was not opened").arg(scene));
        return true;
    }
    if (!runOnOpen && !isLive()) runCulling();
    selectFirstMissOfRun(service_->lastGeneration());
    statusBar()->showMessage(tr("Hunt: %1 at trial %2; the repro is open").arg(
                                 QString::fromStdString(f.verdict.property)).arg(f.trial),
                             15000);
    return true;
}

} // namespace lcui
