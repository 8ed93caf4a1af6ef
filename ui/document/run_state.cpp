#include "document/run_state.hpp"

namespace lcui {

void RunState::setSettings(const lc::CullSettings& s) {
    settings_ = s;
    emit settingsChanged();
}

void RunState::setBackend(const QString& name) {
    if (name == backend_) return;
    backend_ = name;
    emit backendChanged();
}

void RunState::setDevice(const QString& selector) {
    if (selector == device_) return;
    device_ = selector;
    emit backendChanged();
}

void RunState::setLive(bool on) {
    if (on == live_) return;
    live_ = on;
    emit liveChanged(on);
}

bool RunState::setRunOutput(std::shared_ptr<const lc::RunOutput> run, quint64 generation) {
    if (generation < generation_) return false;
    // A run nobody noted (a test's) counts as made from the scene as it is.
    runRevision_ = sceneRevision_;
    for (const auto& [g, revision] : pending_)
        if (g == generation) runRevision_ = revision;
    // A generation answers twice (lists, then truth); older ones never will.
    std::erase_if(pending_, [generation](const auto& p) { return p.first < generation; });
    if (generation != generation_) emit generationChanging();
    run_ = std::move(run);
    generation_ = generation;
    ++revision_;
    emit runOutputChanged();
    return true;
}

void RunState::afterSceneEdit() {
    // After every receiver: a Live re-run asked for by one of them is on its way.
    if (runIsStale()) emit runWentStale();
}

void RunState::noteRunRequested(quint64 generation) {
    pending_.emplace_back(generation, sceneRevision_);
    ++revision_;
}

void RunState::noteRunFailed(quint64 generation) {
    std::erase_if(pending_, [generation](const auto& p) { return p.first == generation; });
    ++revision_;
    if (runIsStale()) emit runWentStale(); // the scene may now be without a run on its way
}

bool RunState::runIsStale() const {
    if (!run_ || runRevision_ == sceneRevision_) return false;
    for (const auto& p : pending_)
        if (p.second == sceneRevision_) return false;
    return true;
}

} // namespace lcui
