#include "cull_worker.hpp"

#include "culling/errors.hpp"
#include "culling/projection.hpp"
#include "culling/shade.hpp"

#include <algorithm>
#include <chrono>
#include <exception>
#include <numeric>
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
    if (cancel_) cancel_->cancelled = true;
    if (truthCancel_) truthCancel_->cancelled = true;
    if (shadeCancel_) shadeCancel_->cancelled = true;
    shadeWanted_ = 0;
}

quint64 CullWorker::droppedRequests() const {
    std::lock_guard lock(mutex_);
    return dropped_;
}

namespace {
// Wall time one slice of shadeInSlices aims at: how long a newer request may
// wait for shading it cancels.
constexpr double kShadeSliceMs = 100.0;

// Rows [y0, y1) of a G-buffer.
lc::ShadeInputs rowsOf(const lc::ShadeInputs& in, std::uint32_t y0, std::uint32_t y1) {
    lc::ShadeInputs s;
    s.width = in.width;
    s.height = y1 - y0;
    const std::size_t a = std::size_t(in.width) * y0, b = std::size_t(in.width) * y1;
    s.position.assign(in.position.begin() + std::ptrdiff_t(3 * a), in.position.begin() + std::ptrdiff_t(3 * b));
    s.normal.assign(in.normal.begin() + std::ptrdiff_t(3 * a), in.normal.begin() + std::ptrdiff_t(3 * b));
    s.list.assign(in.list.begin() + std::ptrdiff_t(a), in.list.begin() + std::ptrdiff_t(b));
    return s;
}

// One image of the shading pass in row slices on `backend`, checking `cancel`
// between slices. Returns RGB (3 floats per pixel) and adds the backend's
// shading time to `shadeMs`. Slices start on multiples of `align` rows, where
// the CPU reference's own row bands start, so each pixel gets the arithmetic
// of one whole-image call (the ui test compares with the CLI's PNGs and RMSE).
std::vector<float> shadeImageInSlices(lc::CullBackend& backend, const lc::ShadeInputs& in,
                                      const lc::ViewLights& lights, const lc::CullResult* culled,
                                      std::uint32_t align, const lc::CancelToken& cancel, double& shadeMs) {
    std::vector<float> rgb(in.position.size(), 0.0f);
    std::uint32_t rows = align;
    for (std::uint32_t y0 = 0; y0 < in.height;) {
        const std::uint32_t y1 = std::min(in.height, y0 + rows);
        const auto t0 = std::chrono::steady_clock::now();
        const std::vector<float> part = backend.shade(rowsOf(in, y0, y1), lights, culled);
        const double wallMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        shadeMs += backend.lastShadeMs() >= 0 ? backend.lastShadeMs() : wallMs;
        std::copy(part.begin(), part.end(), rgb.begin() + std::ptrdiff_t(std::size_t(in.width) * y0 * 3));
        if (cancel.cancelled) throw lc::Cancelled();
        // The next slice: as many aligned rows as fit kShadeSliceMs at this rate.
        const double perRowMs = std::max(wallMs, 1e-3) / double(y1 - y0);
        rows = std::max(align, std::uint32_t(kShadeSliceMs / perRowMs) / align * align);
        y0 = y1;
    }
    return rgb;
}

// lc::shadeAndCompare, sliced so that a newer request stops it within about
// kShadeSliceMs: whole images cost seconds with many lights (the all-lights
// image is pixels x lights; docs/STUDIO.md has the measured times).
void shadeInSlices(lc::CullBackend& backend, lc::RunOutput& out, const lc::Projection& proj,
                   const lc::CancelToken& cancel) {
    const lc::CullResult& r = out.result;
    const lc::ShadeInputs culledIn = lc::makeShadeInputs(out.depth, proj, &r);
    // shadeCpu's row bands: a tile row (at least 4) for lists, 16 rows for all lights.
    const std::uint32_t align = std::lcm(std::max(r.grid.tileSize, 4u), 16u);
    double culledMs = 0, allMs = 0;
    std::vector<float> culled = shadeImageInSlices(backend, culledIn, out.lights, &r, align, cancel, culledMs);
    // `all` with one list of every light in order shades exactly the reference.
    bool identity = r.listCount.size() == 1 && r.listCount[0] == out.lights.size();
    for (std::size_t i = 0; identity && i < out.lights.size(); ++i)
        identity = r.lightIndices[r.listOffset[0] + i] == i;
    std::vector<float> all;
    if (identity) {
        all = culled;
    } else {
        lc::ShadeInputs allIn = culledIn;
        for (std::uint32_t& l : allIn.list)
            if (l != lc::ShadeInputs::kNoList) l = 0;
        all = shadeImageInSlices(backend, allIn, out.lights, nullptr, align, cancel, allMs);
    }
    const lc::ImageError e = lc::compareShadedImages(out.depth, culled, all);
    out.result.timings.shadeMs = culledMs; // as runPipeline: the culled image
    out.truth.metrics.imageRmse = e.rmse;
    out.truth.metrics.imageMaxError = e.maxAbs;
    out.truth.metrics.imageErrorComputed = true;
    out.shadedCulled = std::move(culled);
    out.shadedAll = std::move(all);
}
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
        auto full = std::make_shared<lc::RunOutput>(partial);
        lc::GroundTruthOptions truthOptions;
        truthOptions.imageError = false;
        const auto t0 = std::chrono::steady_clock::now();
        runAtLowPriority([&] {
            full->truth = lc::computeGroundTruth(full->depth, lc::Projection(req.scene->camera), full->lights,
                                                 full->result, truthOptions, truthCancel.get());
        });
        full->result.timings.groundTruthMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        full->truthComputed = true;
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
        shadeInSlices(*backend_, *full, lc::Projection(lastScene_->camera), *cancel);
        last_ = full;
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

void CullWorker::drain() {
    for (;;) {
        CullRequest req;
        std::shared_ptr<lc::CancelToken> cancel = std::make_shared<lc::CancelToken>();
        bool shadeNow = false;
        std::shared_ptr<const lc::RunOutput> resend;
        quint64 unknown = 0;
        {
            std::lock_guard lock(mutex_);
            if (!pending_) {
                const quint64 wanted = std::exchange(shadeWanted_, 0);
                if (wanted == 0) {
                    scheduled_ = false;
                    return;
                }
                // requestShading() for a run that is not running any more.
                if (wanted == lastGeneration_ && last_) {
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
        if (shadeNow) {
            shadeLast();
            continue;
        }
        if (resend) {
            emit finished(lastGeneration_, resend);
            emit shadingEnded(lastGeneration_, true);
            continue;
        }
        if (unknown) {
            emit shadingEnded(unknown, false);
            continue;
        }
        {
            std::lock_guard lock(mutex_);
            req = std::move(*pending_);
            pending_.reset();
            cancel_ = cancel;
        }
        emit started(req.generation);
        try {
            if (!backend_ || req.backend != backendName_ || req.device != deviceSelector_) {
                backend_.reset(); // release the old device before opening a new one
                backendName_.clear();
                depthCamera_.reset();
                depthMeshes_.reset();
                depth_.reset();
                backend_ = lc::makeBackend(req.backend, req.device);
                backendName_ = req.backend;
                deviceSelector_ = req.device;
                emit backendReady(QString::fromStdString(backend_->name()),
                                  QString::fromStdString(backend_->deviceName()));
            }
            lc::RunOptions options;
            // The Lambert image error (pixels x lights) is left to the shading
            // phase below, which runs only when asked (CullRequest::shade).
            options.truthOptions.imageError = false;
            const bool reuse = sameGeometry(req);
            if (reuse) options.reuseDepth = depth_.get();
            // Rendering depth needs the meshes: a scene with them, built here
            // (worker thread) and only then.
            std::shared_ptr<const lc::Scene> runScene = req.scene;
            if (!reuse && req.meshes && runScene->meshes.empty() && !req.meshes->empty()) {
                auto full = std::make_shared<lc::Scene>(*req.scene);
                full->meshes = *req.meshes;
                runScene = std::move(full);
            }
            options.groundTruth = !req.deferTruth;
            auto out = std::make_shared<lc::RunOutput>(
                lc::runPipeline(*runScene, req.settings, *backend_, options, cancel.get()));
            if (!out->depthReused) {
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
                    continue; // superseded: so is its shading
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
                             quint64 geometryRevision) {
    CullRequest r;
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
