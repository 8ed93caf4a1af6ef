#pragma once
// Culling off the UI thread. A CullWorker lives on its own QThread and owns the
// backends (and with them the one Vulkan device); the UI posts requests through
// CullService and gets results back through queued signals.
//
// Long work that needs a backend (the Report dock's sweep) runs here too, as
// a job (CullService::runJob): on the worker's thread and backends, never a
// second device. A job serves the culling requests that arrive while it runs
// between its steps (CullJobContext::serve), so Live stays live during a sweep.
//
// "Latest request wins": the worker has one pending slot, not a queue. A request
// posted while another is still waiting replaces it (dragging a light in Live
// mode must not pile up runs); the run already in progress finishes, and the
// document keeps the result with the highest generation number.

#include "culling/capture/capture_frame.hpp"
#include "culling/core/backend.hpp"
#include "culling/custom/custom_cull.hpp"
#include "culling/core/pipeline.hpp"

#include <QObject>
#include <QString>
#include <QThread>

#include <memory>
#include <mutex>
#include <optional>
#include <condition_variable>
#include <deque>
#include <functional>
#include <map>
#include <vector>

namespace lcui {

struct CullRequest {
    quint64 generation = 0;
    std::shared_ptr<const lc::Scene> scene;
    lc::CullSettings settings;
    std::string backend; // "cpu", "vulkan"
    std::string device;  // selector for makeBackend (empty: default)
    // A Live edit: the result is sent as soon as the lists exist, and ground
    // truth follows as a second result of the same generation unless a newer
    // request arrives first (ground truth costs more than culling, so a drag
    // would otherwise be paced by it).
    bool deferTruth = false;
    // The meshes, apart from `scene` (whose meshes are then empty): shared by
    // every request of one Document::geometryRevision, so a Live drag copies
    // lights and camera only. `geometryRevision` 0: unknown (compared by value).
    std::shared_ptr<const std::vector<lc::Mesh>> meshes;
    quint64 geometryRevision = 0;
    // Shade the culled and the all-lights image (lc::shadeAndCompare, on the
    // request's backend, at the camera's resolution) once the lists (and
    // ground truth) are out: a further result of the same generation that
    // carries RunOutput::shadedCulled/shadedAll and the image error. A newer
    // request cancels shading that has not finished.
    bool shade = false;
    // A custom culling shader (docs/CUSTOM_CULLING.md) instead of
    // settings.algorithm; null: the built-in algorithm.
    std::shared_ptr<const lc::CustomShaderOptions> custom;
    // A RenderDoc capture's frame (File > Open RenderDoc capture...). With
    // `captureLists` its lists are judged (lc::checkCaptureFrame, the scene's
    // lights for the capture's); without, the built-in algorithm or custom
    // shader culls on the capture's depth instead of a pre-pass (the scene
    // has no meshes to draw). Its camera must be the scene's.
    std::shared_ptr<const lc::CaptureFrame> capture;
    bool captureLists = false;
};

// What a job gets: the worker's backends, and a way to let waiting culling
// requests run between its steps. Only on the worker's thread, during the job.
class CullJobContext {
public:
    virtual ~CullJobContext() = default;
    // The worker's backend of that name (opened on first use; its device
    // selector is the last culling request's). Throws lc::Error as
    // lc::makeBackend does.
    virtual lc::CullBackend& backend(const std::string& name) = 0;
    // Runs the culling requests (and shading) waiting now, then returns.
    virtual void serve() = 0;
};
using CullJob = std::function<void(CullJobContext&)>;

class CullWorker : public QObject {
    Q_OBJECT
public:
    // Thread-safe: queues `job` after what is waiting; `cancel` is set when
    // the worker shuts down (the job must then end soon).
    void postJob(CullJob job, std::shared_ptr<lc::CancelToken> cancel);
    // Thread-safe: replaces the pending request and wakes the worker.
    void post(CullRequest request);
    // Thread-safe: drops the pending request and cancels the run in progress
    // (used on shutdown).
    void cancelCurrent();
    // Requests that were replaced before they ran (for diagnostics and tests).
    quint64 droppedRequests() const;
    // Thread-safe: asks for the shaded images of run `generation` (the camera
    // view switched to a shaded mode, or an export needs them). A run still
    // queued or running shades when its lists are out; the last finished run
    // is shaded now (or, already shaded, sent again). Any other generation
    // ends at once with shadingEnded(generation, false).
    void requestShading(quint64 generation);
    // Thread-safe: stops the shading pass in progress (the status bar's
    // Cancel); it ends with shadingEnded(generation, false) and the run keeps
    // its lists and ground truth.
    void cancelShading();

signals:
    void started(quint64 generation);
    void finished(quint64 generation, std::shared_ptr<const lc::RunOutput> output);
    void failed(quint64 generation, QString message);
    void backendReady(QString name, QString device);
    // The shading pass of `generation` starts / ends (`shaded`: its images
    // were sent with finished(); false: cancelled, failed or not possible).
    void shadingStarted(quint64 generation);
    void shadingProgress(quint64 generation, double fraction);
    void shadingEnded(quint64 generation, bool shaded);

private slots:
    void drain();

private:
    class JobContext;
    // One step of drain(): a waiting request, shading asked for, or (with
    // `jobs`) a job. False when there was nothing to do.
    bool drainOne(bool jobs);
    void runRequest(CullRequest req, std::shared_ptr<lc::CancelToken> cancel);
    // The backend `name` on `device`, opened on first use; another device
    // selector closes every backend first (one device at a time).
    lc::CullBackend& backendFor(const std::string& name, const std::string& device);
    // Second phase of a deferTruth request (worker thread); null when a newer
    // request superseded it.
    std::shared_ptr<const lc::RunOutput> addDeferredTruth(const CullRequest& req, const lc::RunOutput& partial);
    // Last phase: shades last_ (worker thread). False when cancelled or failed.
    bool shadeLast();

private:
    mutable std::mutex mutex_;
    std::condition_variable posted_; // post(): wakes a deferred ground truth waiting for a pause
    std::optional<CullRequest> pending_;
    bool scheduled_ = false;
    quint64 dropped_ = 0;
    std::shared_ptr<lc::CancelToken> cancel_;
    std::shared_ptr<lc::CancelToken> truthCancel_; // set by post(): a newer request stops deferred truth
    std::shared_ptr<lc::CancelToken> shadeCancel_; // likewise for shading
    quint64 shadeWanted_ = 0;                      // requestShading()'s generation, 0: none
    std::deque<std::pair<CullJob, std::shared_ptr<lc::CancelToken>>> jobs_;
    std::shared_ptr<lc::CancelToken> jobCancel_; // the running job's
    // Touched only on the worker thread:
    std::map<std::string, std::unique_ptr<lc::CullBackend>> backends_; // by name, on deviceSelector_
    lc::CullBackend* backend_ = nullptr; // the culling requests' (one of backends_)
    bool inJob_ = false;
    std::string backendName_, deviceSelector_;
    // The last run's scene and depth: a request that changes only lights (a
    // Live drag) reuses the depth image instead of re-rendering it.
    // What the depth image was rendered from: camera, meshes and revision.
    bool sameGeometry(const CullRequest& req) const;
    std::optional<lc::Camera> depthCamera_;
    std::shared_ptr<const std::vector<lc::Mesh>> depthMeshes_;
    quint64 depthRevision_ = 0;
    std::shared_ptr<const lc::DepthImage> depth_;
    std::string depthSource_; // who drew depth_: "pre-pass on cpu (device)"
    // The last finished run (its most complete output) and its request: what
    // requestShading() shades.
    quint64 lastGeneration_ = 0;
    std::shared_ptr<const lc::Scene> lastScene_;
    std::shared_ptr<const lc::RunOutput> last_;
    // The last run shaded on backend_, with its scene: its all-lights image
    // serves a later run with the same pixels (lc::samePixels), kept as it is
    // when the lights are the same too (the user compares algorithms in a
    // shaded mode) or updated for the few that changed (a dragged light).
    std::shared_ptr<const lc::RunOutput> shaded_;
    std::shared_ptr<const lc::Scene> shadedScene_;
};

// The UI-side handle: starts the thread, numbers the requests.
class CullService : public QObject {
    Q_OBJECT
public:
    explicit CullService(QObject* parent = nullptr);
    ~CullService() override;

    // Copies the scene and posts it; returns the request's generation. With a
    // `geometryRevision` (Document::geometryRevision) the meshes are copied
    // only when it changes and shared by the requests in between.
    quint64 request(const lc::Scene& scene, const lc::CullSettings& settings,
                    const QString& backend, const QString& device, bool deferTruth = false,
                    bool shade = false, quint64 geometryRevision = 0,
                    std::shared_ptr<const lc::CustomShaderOptions> custom = nullptr,
                    std::shared_ptr<const lc::CaptureFrame> capture = nullptr, bool captureLists = false);
    // CullWorker::requestShading.
    void requestShading(quint64 generation) { worker_->requestShading(generation); }
    // CullWorker::postJob: long work on the worker's thread and backends.
    void runJob(CullJob job, std::shared_ptr<lc::CancelToken> cancel) { worker_->postJob(std::move(job), std::move(cancel)); }
    quint64 lastGeneration() const { return generation_; }
    // The meshes the last request shared with the worker (see CullRequest::meshes).
    std::shared_ptr<const std::vector<lc::Mesh>> meshSnapshot() const { return meshes_; }
    CullWorker* worker() { return worker_; }
    // "vulkan" when this build and machine have it, else "cpu".
    static QString defaultBackend();

signals:
    void started(quint64 generation);
    void finished(quint64 generation, std::shared_ptr<const lc::RunOutput> output);
    void failed(quint64 generation, QString message);
    void backendReady(QString name, QString device);
    void shadingStarted(quint64 generation);
    void shadingProgress(quint64 generation, double fraction);
    void shadingEnded(quint64 generation, bool shaded);

private:
    QThread thread_;
    CullWorker* worker_;
    quint64 generation_ = 0;
    std::shared_ptr<const std::vector<lc::Mesh>> meshes_;
    quint64 meshesRevision_ = 0;
};

} // namespace lcui

Q_DECLARE_METATYPE(std::shared_ptr<const lc::RunOutput>)
