#pragma once
// What to cull and what came back: the culling settings, the backend and
// whether Live re-culls on every edit (the toolbar's controls show these; they
// do not hold them), and the latest finished run with its staleness. Part of
// the Document (document.hpp), which counts its scene's edits here.

#include "culling/core/params.hpp"
#include "culling/core/pipeline.hpp"

#include <QObject>
#include <QString>

#include <memory>
#include <utility>
#include <vector>

namespace lcui {

class RunState : public QObject {
    Q_OBJECT
public:
    using QObject::QObject;

    // --- what to run (not part of the scene, not undoable) -----------------------
    const lc::CullSettings& settings() const { return settings_; }
    void setSettings(const lc::CullSettings& s);
    // "vulkan" or "cpu" (lc::availableBackends); empty until the window sets it.
    const QString& backend() const { return backend_; }
    void setBackend(const QString& name);
    // The Vulkan device selector (an index or a name's part; empty: the default).
    const QString& device() const { return device_; }
    void setDevice(const QString& selector);
    // Live: every scene edit and settings change asks for a run at once.
    bool live() const { return live_; }
    void setLive(bool on);

    // --- the latest run ----------------------------------------------------------
    // The newest finished run, or null. `generation` is the request number the
    // worker answered; older generations than the one shown are dropped.
    std::shared_ptr<const lc::RunOutput> runOutput() const { return run_; }
    quint64 runGeneration() const { return generation_; }
    // Returns false (and ignores it) when `generation` is older than the shown one.
    bool setRunOutput(std::shared_ptr<const lc::RunOutput> run, quint64 generation);
    // A run asked for the scene as it is now (its result, when it comes,
    // belongs to this scene), or that run failed.
    void noteRunRequested(quint64 generation);
    void noteRunFailed(quint64 generation);
    // The shown run was made from an earlier scene (an edit since), and no run
    // of the scene as it is now is on its way: its lists, truth and light
    // indices no longer describe the scene, so what reads them per light (the
    // tile inspector, Explain, the export) must not. A Live edit's run is on
    // its way at once, so Live does not go stale.
    bool runIsStale() const;

    // --- for the Document ----------------------------------------------------------
    // The scene was edited (before the edit's receivers run) / all receivers ran
    // (emits runWentStale when no run of the scene as it is is on its way).
    void noteSceneEdit() {
        ++sceneRevision_;
        ++revision_;
    }
    void afterSceneEdit();
    // A new scene: no run shown. Silent, like Selection::reset.
    void resetRun() {
        run_.reset();
        ++revision_;
    }

    // Counts every change of the shown run or of what makes it stale (what is
    // worked out from the run is kept while it is the same).
    quint64 revision() const { return revision_; }

signals:
    void settingsChanged();
    void backendChanged(); // also when the device selector changes
    void liveChanged(bool on);
    // A run of another generation than the shown one is about to be shown
    // (before runOutputChanged: what indexes the old lists forgets them).
    void generationChanging();
    void runOutputChanged();
    // The shown run became stale (runIsStale): after an edit's receivers
    // have all run, or when the run asked for the scene as it is failed.
    void runWentStale();

private:
    lc::CullSettings settings_;
    QString backend_, device_;
    bool live_ = false;
    std::shared_ptr<const lc::RunOutput> run_;
    quint64 generation_ = 0;
    // Scene edits counted, the count the shown run was asked for, and the
    // runs asked for and not yet answered.
    quint64 sceneRevision_ = 0, runRevision_ = 0;
    std::vector<std::pair<quint64, quint64>> pending_; // generation, scene revision
    quint64 revision_ = 0;
};

} // namespace lcui
