#pragma once
// File > Export diagnostics: summary.json, tiles.csv, heatmap.png,
// overlays.vtm, the shaded images and PNG screenshots of both views, through
// the CLI's lc::exportDiagnostics, atomically into a new folder.
//
// The shaded images come with every export: a run the camera view showed as
// a heat map is shaded on the culling worker first. The export then waits for
// that result as any other (no nested event loop: the window stays live, and
// an edit in the meantime does not change what is exported: the scene, the
// run and the views' screenshots are taken when the export is asked for).

#include "culling/diagnostics/export.hpp"
#include "culling/scene/scene.hpp"

#include <QMetaObject>
#include <QObject>
#include <QString>

#include <memory>
#include <vector>

namespace lc {
struct RunOutput;
}

namespace lcui {

class CameraView;
class CullService;
class Document;
class InspectorView;

class DiagnosticsExport : public QObject {
    Q_OBJECT
public:
    DiagnosticsExport(Document* doc, CullService* service, CameraView* camera, InspectorView* inspector,
                      QObject* parent);

    // Exports the shown run into `dir`. Ends with finished(): before start()
    // returns when the run has its shaded images, else once the worker has
    // shaded it. False (and finished(dir, false, why) at once) when there is
    // no run, the scene changed since it, or an export is under way.
    bool start(const QString& dir);
    bool busy() const { return pending_ != nullptr; }

signals:
    // `ok`: written; else `message` says why nothing was.
    void finished(const QString& dir, bool ok, const QString& message);

private:
    struct Pending {
        QString dir;
        quint64 generation = 0;
        lc::Scene scene;
        std::vector<lc::NamedImage> views;
    };
    void write(const Pending& p, const lc::RunOutput& run);
    void end(const QString& dir, bool ok, const QString& message);

    Document* doc_;
    CullService* service_;
    CameraView* camera_;
    InspectorView* inspector_;
    std::unique_ptr<Pending> pending_; // waiting for its run's shaded images
};

} // namespace lcui
