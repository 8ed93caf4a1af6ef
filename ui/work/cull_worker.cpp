#include "work/cull_worker.hpp"

#include "culling/core/errors.hpp"
#include "culling/math/projection.hpp"

#include <chrono>
#include <exception>
#include <thread>
#include <utility>

#ifdef __linux__
#include <sys/resource.h>
#include <unistd.h>
#endif

#include <QMetaObject>

namespace lcui {

namespace {
bool sameMeshes(const std::vector<lc::Mesh>& a, const std::vector<lc::Mesh>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const lc::Mesh &x = a[i], &y = b[i];
        if (x.transform != y.transform || x.positions != y.positions || x.indices != y.indices) return false;
    }
    return true;
}

// A Live edit's ground truth starts once no edit came for this long (or at
// once when the worker is otherwise idle at the end of a drag): during a drag
// it would take the CPU from the views' redraw, and the next edit cancels it.
constexpr auto kTruthAfterPause = std::chrono::milliseconds(150);

// Runs `fn` on a thread of its own at nice 10 (Linux: per thread; the ground
// truth's row-band threads inherit it), then rethrows what `fn` threw. A
// deferred truth that the next edit of a drag cancels then takes little CPU
// from the views' redraw (about a fifth of the culling thread's samples went
// to such truths at nice 0); once the drag stops the machine is idle and it
// runs at full speed. Not SCHED_IDLE: on a busy machine (a CI run) that could
// starve the truth.
template <typename Fn>
void runAtLowPriority(Fn&& fn) {
    std::exception_ptr error;
    std::thread t([&] {
#ifdef __linux__
        setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), 10); // best effort
#endif
        try {
            fn();
        } catch (...) {
            error = std::current_exception();
        }
    });
    t.join();
    if (error) std::rethrow_exception(error);
}
} // namespace

// Same camera and meshes: the depth image of one is the depth of the other.
// The same geometry revision means the same meshes (no comparison by value).
bool CullWorker::sameGeometry(const CullRequest& req) const {
    if (!depth_ || !depthCamera_ || !(*depthCamera_ == req.scene->camera)) return false;
    if (req.geometryRevision != 0) return req.geometryRevision == depthRevision_;
    const std::vector<lc::Mesh>& meshes = req.meshes ? *req.meshes : req.scene->meshes;
    return depthMeshes_ && (depthMeshes_.get() == &meshes || sameMeshes(*depthMeshes_, meshes));
}

void CullWorker::post(CullRequest request) {
    bool schedule = false;
    {
        std::lock_guard lock(mutex_);
        if (pending_) ++dropped_;
        pending_ = std::move(request);
        if (truthCancel_) truthCancel_->cancelled = true;
        if (shadeCancel_) shadeCancel_->cancelled = true;
        if (!scheduled_) scheduled_ = schedule = true;
    }
    posted_.notify_all();
    if (schedule) QMetaObject::invokeMethod(this, "drain", Qt::QueuedConnection);
}

void CullWorker::requestShading(quint64 generation) {
    bool schedule = false;
    {
        std::lock_guard lock(mutex_);
        shadeWanted_ = generation;
        if (!scheduled_) scheduled_ = schedule = true;
    }
    if (schedule) QMetaObject::invokeMethod(this, "drain", Qt::QueuedConnection);
}

void CullWorker::cancelCurrent() {
    std::lock_guard lock(mutex_);
    pending_.reset();
    for (auto& j : jobs_) j.second->cancelled = true;
    jobs_.clear();
    if (jobCancel_) jobCancel_->cancelled = true;
    if (cancel_) cancel_->cancelled = true;
    if (truthCancel_) truthCancel_->cancelled = true;
    if (shadeCancel_) shadeCancel_->cancelled = true;
    shadeWanted_ = 0;
}

void CullWorker::cancelShading() {
    std::lock_guard lock(mutex_);
    if (shadeCancel_) shadeCancel_->cancelled = true;
    shadeWanted_ = 0;
}

quint64 CullWorker::droppedRequests() const {
    std::lock_guard lock(mutex_);
    return dropped_;
}

namespace {
// Wall time of one shading slice (lc::shadeAndCompare's sliceMs): how long a
// newer request may wait for shading it cancels. Whole images cost seconds
// with many lights (the all-lights image is pixels x lights; docs/STUDIO.md
// has the measured times).
constexpr double kShadeSliceMs = 100.0;
} // namespace

std::shared_ptr<const lc::RunOutput> CullWorker::addDeferredTruth(const CullRequest& req,
                                                                  const lc::RunOutput& partial) {
    auto truthCancel = std::make_shared<lc::CancelToken>();
    std::shared_ptr<const lc::RunOutput> done;
    {
        std::unique_lock lock(mutex_);
        // The newer request will bring its own.
        if (posted_.wait_for(lock, kTruthAfterPause, [this] { return pending_.has_value(); })) return done;
        truthCancel_ = truthCancel;
    }
    try {
        // The pipeline's own truth phase (lc::judgeRun: truth, its time),
        // run later; the image error stays with the shading phase.
        auto full = std::make_shared<lc::RunOutput>(partial);
        lc::RunOptions truthOnly;
        truthOnly.groundTruth = true;
        truthOnly.truthOptions.imageError = false;
        runAtLowPriority([&] {
            lc::judgeRun(*full, lc::Projection(req.scene->camera), *backend_, truthOnly, truthCancel.get());
        });
        done = std::move(full);
        emit finished(req.generation, done);
    } catch (const lc::Cancelled&) {
        // A newer request arrived: its run supersedes this truth.
    }
    std::lock_guard lock(mutex_);
    if (truthCancel_ == truthCancel) truthCancel_.reset();
    return done;
}

bool CullWorker::shadeLast() {
    const quint64 generation = lastGeneration_;
    auto cancel = std::make_shared<lc::CancelToken>();
    {
        std::lock_guard lock(mutex_);
        if (shadeWanted_ == generation) shadeWanted_ = 0;
        if (pending_) {
            // A newer request runs first and brings its own images if wanted.
            emit shadingEnded(generation, false);
            return false;
        }
        shadeCancel_ = cancel;
    }
    emit shadingStarted(generation);
    bool shaded = false;
    try {
        if (cancel->cancelled) throw lc::Cancelled();
        auto full = std::make_shared<lc::RunOutput>(*last_);
        const bool same = shaded_ && lc::samePixels(*shaded_, shadedScene_->camera, *full, lastScene_->camera);
        lc::shadeAndCompare(*backend_, *full, lc::Projection(lastScene_->camera), true, cancel.get(),
                            kShadeSliceMs, [this, generation](double f) { emit shadingProgress(generation, f); },
                            same ? shaded_.get() : nullptr);
        last_ = full;
        shaded_ = full;
        shadedScene_ = lastScene_;
        shaded = true;
        emit finished(generation, last_);
    } catch (const lc::Cancelled&) {
        // A newer request supersedes these images.
    } catch (const std::exception& e) {
        emit failed(generation, tr("shading: %1").arg(QString::fromStdString(e.what())));
    }
    {
        std::lock_guard lock(mutex_);
        if (shadeCancel_ == cancel) shadeCancel_.reset();
    }
    emit shadingEnded(generation, shaded);
    return shaded;
}

class CullWorker::JobContext : public CullJobContext {
public:
    explicit JobContext(CullWorker& w) : w_(w) {}
    lc::CullBackend& backend(const std::string& name) override {
        return w_.backendFor(name, w_.deviceSelector_);
    }
    void serve() override {
        while (w_.drainOne(false)) {
        }
    }

private:
    CullWorker& w_;
};

void CullWorker::postJob(CullJob job, std::shared_ptr<lc::CancelToken> cancel) {
    bool schedule = false;
    {
        std::lock_guard lock(mutex_);
        jobs_.emplace_back(std::move(job), std::move(cancel));
        if (!scheduled_) scheduled_ = schedule = true;
    }
    if (schedule) QMetaObject::invokeMethod(this, "drain", Qt::QueuedConnection);
}

lc::CullBackend& CullWorker::backendFor(const std::string& name, const std::string& device) {
    if (device != deviceSelector_) {
        // A job holds its backends across its steps: no device change under it.
        if (inJob_)
            throw lc::Error("device '" + device + "': the Report's sweep is running on device '" + deviceSelector_ +
                            "'; change the device once it ends (or cancel it)");
        backend_ = nullptr;
        backends_.clear(); // release the old device before opening a new one
        deviceSelector_ = device;
    }
    auto& b = backends_[name];
    if (!b) {
        try {
            b = lc::makeBackend(name, device);
        } catch (...) {
            backends_.erase(name);
            throw;
        }
    }
    return *b;
}

void CullWorker::drain() {
    while (drainOne(true)) {
    }
}

bool CullWorker::drainOne(bool jobs) {
    std::shared_ptr<lc::CancelToken> cancel = std::make_shared<lc::CancelToken>();
    bool shadeNow = false;
    std::shared_ptr<const lc::RunOutput> resend;
    quint64 unknown = 0;
    std::optional<std::pair<CullJob, std::shared_ptr<lc::CancelToken>>> job;
    {
        std::lock_guard lock(mutex_);
        if (!pending_) {
            const quint64 wanted = std::exchange(shadeWanted_, 0);
            if (wanted == 0) {
                if (!jobs || jobs_.empty()) {
                    if (jobs) scheduled_ = false; // a job's serve() leaves drain() scheduled
                    return false;
                }
                job = std::move(jobs_.front());
                jobs_.pop_front();
                jobCancel_ = job->second;
            } else if (wanted == lastGeneration_ && last_) {
                // requestShading() for a run that is not running any more.
                if (last_->shadedAll.empty()) {
                    shadeWanted_ = wanted;
                    shadeNow = true;
                } else {
                    resend = last_;
                }
            } else {
                unknown = wanted;
            }
        }
    }
    if (job) {
        JobContext context(*this);
        struct InJob {
            bool& flag;
            ~InJob() { flag = false; }
        } inJob{inJob_ = true};
        job->first(context); // the job reports its own result and errors
        std::lock_guard lock(mutex_);
        jobCancel_.reset();
        return true;
    }
    if (shadeNow) {
        shadeLast();
        return true;
    }
    if (resend) {
        emit finished(lastGeneration_, resend);
        emit shadingEnded(lastGeneration_, true);
        return true;
    }
    if (unknown) {
        emit shadingEnded(unknown, false);
        return true;
    }
    CullRequest req;
    {
        std::lock_guard lock(mutex_);
        req = std::move(*pending_);
        pending_.reset();
        cancel_ = cancel;
    }
    runRequest(std::move(req), std::move(cancel));
    return true;
}

void CullWorker::runRequest(CullRequest req, std::shared_ptr<lc::CancelToken> cancel) {
    emit started(req.generation);
    try {
        if (!backend_ || req.backend != backendName_ || req.device != deviceSelector_) {
            shaded_.reset(); // its images are the old backend's
            backendName_.clear();
            depthCamera_.reset();
            depthMeshes_.reset();
            depth_.reset();
            backend_ = &backendFor(req.backend, req.device);
            backendName_ = req.backend;
            emit backendReady(QString::fromStdString(backend_->name()), QString::fromStdString(backend_->deviceName()));
        }
        lc::RunOptions options;
        // The Lambert image error (pixels x lights) is left to the shading
        // phase below, which runs only when asked (CullRequest::shade).
        options.truthOptions.imageError = false;
        const bool reuse = !req.capture && sameGeometry(req);
        if (reuse) options.reuseDepth = depth_.get();
        if (req.capture) {
            if (!(req.scene->camera == req.capture->scene.camera))
                throw lc::InputError(req.capture->source, "camera", 0,
                                     "the camera is not the capture's: its depth and lists are for the capture's "
                                     "camera (Edit > Undo brings it back)");
            options.reuseDepth = &req.capture->depth;
        }
        // Rendering depth needs the meshes: a scene with them, built here
        // (worker thread) and only then.
        std::shared_ptr<const lc::Scene> runScene = req.scene;
        if (!reuse && req.meshes && runScene->meshes.empty() && !req.meshes->empty()) {
            auto full = std::make_shared<lc::Scene>(*req.scene);
            full->meshes = *req.meshes;
            runScene = std::move(full);
        }
        options.groundTruth = !req.deferTruth;
        std::shared_ptr<lc::RunOutput> out;
        if (req.captureLists) {
            lc::CustomCullReport report;
            out = std::make_shared<lc::RunOutput>(lc::checkCaptureFrame(*req.capture, options, report, runScene.get()));
        } else if (req.custom) {
            lc::CustomCullReport report;
            out = std::make_shared<lc::RunOutput>(
                lc::runCustomPipeline(*runScene, *req.custom, *backend_, options, report, options.reuseDepth));
        } else {
            out = std::make_shared<lc::RunOutput>(
                lc::runPipeline(*runScene, req.settings, *backend_, options, cancel.get()));
        }
        // A reused depth names the rasteriser that drew it: a custom
        // shader or another algorithm reuses a pre-pass drawn by the
        // backend of an earlier run, and rasterisers differ at edges.
        if (req.capture) {
            out->depthFrom = lc::captureDepthSource(*req.capture);
            depth_.reset(); // the next run without a capture draws its own
            depthCamera_.reset();
        } else if (out->depthReused) {
            out->depthFrom = "the previous run's " + depthSource_ + " (camera and meshes unchanged)";
        } else {
            depthSource_ = out->depthFrom.empty() ? "pre-pass on " + backend_->name() + " (" + backend_->deviceName() + ")"
                                                  : out->depthFrom;
            depth_ = std::make_shared<const lc::DepthImage>(out->depth);
            depthCamera_ = req.scene->camera;
            depthMeshes_ = req.meshes;
            if (!depthMeshes_) depthMeshes_ = std::make_shared<const std::vector<lc::Mesh>>(req.scene->meshes);
            depthRevision_ = req.geometryRevision;
        }
        emit finished(req.generation, std::shared_ptr<const lc::RunOutput>(out));
        lastGeneration_ = req.generation;
        lastScene_ = req.scene;
        last_ = out;
        if (req.deferTruth) {
            last_ = addDeferredTruth(req, *out);
            if (!last_) {
                last_ = out;
                return; // superseded: so is its shading
            }
        }
        bool shade = req.shade;
        {
            std::lock_guard lock(mutex_);
            shade = shade || shadeWanted_ == req.generation;
        }
        if (shade) shadeLast();
    } catch (const lc::Cancelled&) {
        emit failed(req.generation, tr("culling cancelled"));
    } catch (const std::exception& e) {
        emit failed(req.generation, QString::fromStdString(e.what()));
    }
}

CullService::CullService(QObject* parent) : QObject(parent), worker_(new CullWorker) {
    qRegisterMetaType<std::shared_ptr<const lc::RunOutput>>();
    thread_.setObjectName("CullWorker");
    worker_->moveToThread(&thread_);
    connect(&thread_, &QThread::finished, worker_, &QObject::deleteLater);
    connect(worker_, &CullWorker::started, this, &CullService::started, Qt::QueuedConnection);
    connect(worker_, &CullWorker::finished, this, &CullService::finished, Qt::QueuedConnection);
    connect(worker_, &CullWorker::failed, this, &CullService::failed, Qt::QueuedConnection);
    connect(worker_, &CullWorker::backendReady, this, &CullService::backendReady,
            Qt::QueuedConnection);
    connect(worker_, &CullWorker::shadingStarted, this, &CullService::shadingStarted, Qt::QueuedConnection);
    connect(worker_, &CullWorker::shadingProgress, this, &CullService::shadingProgress, Qt::QueuedConnection);
    connect(worker_, &CullWorker::shadingEnded, this, &CullService::shadingEnded, Qt::QueuedConnection);
    thread_.start();
}

CullService::~CullService() {
    worker_->cancelCurrent();
    thread_.quit();
    thread_.wait();
}

quint64 CullService::request(const lc::Scene& scene, const lc::CullSettings& settings,
                             const QString& backend, const QString& device, bool deferTruth, bool shade,
                             quint64 geometryRevision, std::shared_ptr<const lc::CustomShaderOptions> custom,
                             std::shared_ptr<const lc::CaptureFrame> capture, bool captureLists) {
    CullRequest r;
    r.custom = std::move(custom);
    r.capture = std::move(capture);
    r.captureLists = r.capture && captureLists;
    r.generation = ++generation_;
    // Lights and camera are copied; the meshes only when their revision changed.
    auto copy = std::make_shared<lc::Scene>();
    copy->name = scene.name;
    copy->lights = scene.lights;
    copy->camera = scene.camera;
    r.scene = std::move(copy);
    if (geometryRevision == 0 || geometryRevision != meshesRevision_ || !meshes_) {
        meshes_ = std::make_shared<const std::vector<lc::Mesh>>(scene.meshes);
        meshesRevision_ = geometryRevision;
    }
    r.meshes = meshes_;
    r.geometryRevision = geometryRevision;
    r.settings = settings;
    r.backend = backend.toStdString();
    r.device = device.toStdString();
    r.deferTruth = deferTruth;
    r.shade = shade;
    worker_->post(std::move(r));
    return generation_;
}

QString CullService::defaultBackend() {
    for (const auto& b : lc::availableBackends())
        if (b == "vulkan") return "vulkan";
    return "cpu";
}

} // namespace lcui
