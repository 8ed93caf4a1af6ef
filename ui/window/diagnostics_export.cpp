#include "window/diagnostics_export.hpp"

#include "document/document.hpp"
#include "views/camera_view.hpp"
#include "views/inspector_view.hpp"
#include "work/cull_worker.hpp"

#include <QImage>

namespace lcui {

namespace {

lc::RgbImage toRgb(const QImage& image) {
    const QImage img = image.convertToFormat(QImage::Format_RGB888);
    lc::RgbImage out;
    out.width = std::uint32_t(img.width());
    out.height = std::uint32_t(img.height());
    out.rgb.resize(std::size_t(out.width) * out.height * 3);
    for (int y = 0; y < img.height(); ++y)
        std::copy_n(img.constScanLine(y), std::size_t(out.width) * 3, out.rgb.begin() + std::ptrdiff_t(y) * out.width * 3);
    return out;
}

} // namespace

DiagnosticsExport::DiagnosticsExport(Document* doc, CullService* service, CameraView* camera,
                                     InspectorView* inspector, QObject* parent)
    : QObject(parent), doc_(doc), service_(service), camera_(camera), inspector_(inspector) {
    // finished() also reaches the window, which shows the images.
    connect(service_, &CullService::finished, this, [this](quint64 g, std::shared_ptr<const lc::RunOutput> out) {
        if (!pending_ || g != pending_->generation || out->shadedAll.empty()) return;
        const std::unique_ptr<Pending> p = std::move(pending_);
        write(*p, *out);
    });
    connect(service_, &CullService::shadingEnded, this, [this](quint64 g, bool shaded) {
        if (!pending_ || g != pending_->generation || shaded) return;
        const QString dir = pending_->dir;
        pending_.reset();
        end(dir, false,
            tr("the shading pass of run %1 did not finish (cancelled, failed, or a newer run replaced it); nothing "
               "was exported")
                .arg(g));
    });
}

bool DiagnosticsExport::start(const QString& dir) {
    const auto run = doc_->runs().runOutput();
    QString refusal;
    if (pending_)
        refusal = tr("an export into %1 is waiting for its shaded images; nothing was exported").arg(pending_->dir);
    else if (!run)
        refusal = tr("there is no culling run to export yet: press F5");
    // The export pairs the scene with the run's lists and truth light by light.
    else if (doc_->runs().runIsStale())
        refusal = tr("the scene changed since the last culling run: press F5 to run it again, then export; "
                     "nothing was exported");
    if (!refusal.isEmpty()) {
        end(dir, false, refusal);
        return false;
    }
    auto p = std::make_unique<Pending>();
    p->dir = dir;
    p->generation = doc_->runs().runGeneration();
    // Unsaved edits: the export records them and writes the edited scene
    // beside summary.json, so that the figures can be reproduced.
    p->scene = doc_->scene();
    p->scene.origin.edited = doc_->isDirty();
    camera_->renderNow();
    inspector_->renderNow();
    p->views.push_back({"camera_view.png", toRgb(camera_->grabFramebuffer())});
    p->views.push_back({"inspector_view.png", toRgb(inspector_->grabFramebuffer())});
    if (!run->shadedAll.empty()) {
        write(*p, *run);
        return true;
    }
    pending_ = std::move(p);
    service_->requestShading(pending_->generation);
    return true;
}

void DiagnosticsExport::write(const Pending& p, const lc::RunOutput& run) {
    try {
        // The settings the run used (the toolbar may have changed since).
        lc::exportDiagnostics(p.scene, run.result.settings, run, p.dir.toStdString(), p.views);
    } catch (const std::exception& e) {
        end(p.dir, false, QString::fromStdString(e.what()));
        return;
    }
    end(p.dir, true, {});
}

void DiagnosticsExport::end(const QString& dir, bool ok, const QString& message) { emit finished(dir, ok, message); }

} // namespace lcui
