#include "window/scene_files.hpp"

#include "document/document.hpp"
#include "widgets/count_text.hpp"
#include "widgets/status_progress.hpp"
#include "work/progress_task.hpp"

#include "culling/core/errors.hpp"
#include "culling/scene/scene_io.hpp"

#include <QAction>
#include <QElapsedTimer>
#include <QFileInfo>
#include <QMenu>
#include <QSettings>

namespace lcui {

namespace {
constexpr int kMaxRecent = 8;
QString describe(const std::exception& e) { return QString::fromStdString(e.what()); }
} // namespace

SceneFiles::SceneFiles(QWidget* window, Document* doc, StatusProgress* progress, const Prompts& prompts,
                       const lc::GltfReadOptions& gltf)
    : QObject(window), window_(window), doc_(doc), progress_(progress), prompts_(prompts), gltf_(gltf) {}

void SceneFiles::setRecentMenu(QMenu* menu) {
    recentMenu_ = menu;
    rebuildRecentMenu();
}

bool SceneFiles::maybeSave() {
    if (!doc_->isDirty()) return true;
    const QString name = doc_->filePath().isEmpty() ? tr("the scene") : QFileInfo(doc_->filePath()).fileName();
    switch (prompts_.askUnsaved(window_, tr("Save changes to %1?").arg(name))) {
    case QMessageBox::Save: return save();
    case QMessageBox::Discard: return true;
    default: return false;
    }
}

bool SceneFiles::newScene() {
    if (!maybeSave()) return false;
    lc::Scene s;
    s.name = "untitled";
    doc_->resetScene(std::move(s), {});
    log(tr("new scene"));
    return true;
}

bool SceneFiles::openBuiltin(const QString& name) {
    if (!maybeSave()) return false;
    try {
        doc_->resetScene(lc::makeBuiltinScene(name.toStdString()), {});
    } catch (const std::exception& e) {
        log(describe(e), true);
        prompts_.showError(window_, tr("Built-in scene"), describe(e));
        return false;
    }
    emit opened(tr("built-in scene %1").arg(name));
    return true;
}

bool SceneFiles::openSceneFile(const QString& path) {
    if (!maybeSave()) return false;
    const std::string p = path.toStdString();
    lc::GltfReadReport gltfReport;
    QElapsedTimer loadTimer;
    loadTimer.start();
    try {
        lc::Scene s = runWithProgressResult<lc::Scene>(
            progress_, tr("Loading %1...").arg(QFileInfo(path).fileName()),
            [p, o = gltf_, &gltfReport](const lc::CancelToken& c, const lc::Progress& pr) {
                return lc::loadSceneAny(p, o, &gltfReport, &c, pr);
            });
        doc_->resetScene(std::move(s), path);
        for (const std::string& w : gltfReport.warnings) warn(QString::fromStdString(w));
        if (lc::isGltfPath(p))
            log(tr("%1: %2, %3, camera: %4; loaded in %5 ms")
                    .arg(path)
                    .arg(countOf(doc_->scene().triangleCount(), "triangle", "triangles"))
                    .arg(countOf(doc_->scene().lights.size(), "light", "lights"))
                    .arg(QString::fromStdString(gltfReport.camera))
                    .arg(loadTimer.elapsed()));
    } catch (const lc::Cancelled&) {
        log(tr("loading %1 cancelled").arg(path));
        return false;
    } catch (const std::exception& e) {
        log(tr("cannot open %1: %2").arg(path, describe(e)), true);
        prompts_.showError(window_, tr("Open scene"), describe(e));
        return false;
    }
    addRecentFile(path);
    emit opened(path);
    return true;
}

bool SceneFiles::importMeshFile(const QString& path) {
    const std::string p = path.toStdString();
    lc::MeshLoadReport report;
    try {
        lc::Mesh m = runWithProgressResult<lc::Mesh>(
            progress_, tr("Importing %1...").arg(QFileInfo(path).fileName()),
            [p, &report](const lc::CancelToken& c, const lc::Progress& pr) {
                return lc::loadMesh(p, &report, &c, pr);
            });
        if (m.name.empty()) m.name = QFileInfo(path).completeBaseName().toStdString();
        if (m.sourcePath.empty()) m.sourcePath = p;
        const std::size_t tris = m.triangleCount();
        doc_->importMesh(std::move(m));
        log(tr("imported %1: %2 triangles").arg(path).arg(tris));
        if (!report.warning.empty()) warn(QString::fromStdString(report.warning));
    } catch (const lc::Cancelled&) {
        log(tr("import of %1 cancelled").arg(path));
        return false;
    } catch (const std::exception& e) {
        log(tr("cannot import %1: %2").arg(path, describe(e)), true);
        prompts_.showError(window_, tr("Import mesh"), describe(e));
        return false;
    }
    return true;
}

namespace {
// Whether `path` is the glTF file another tool wrote that the scene came from
// (SceneOrigin::foreignGltf): never overwritten.
bool isForeignSource(const lc::Scene& scene, const QString& path) {
    const lc::SceneOrigin& o = scene.origin;
    if (!o.foreignGltf || o.file.empty()) return false;
    const QFileInfo a(path), b(QString::fromStdString(o.file));
    return a.exists() && b.exists() && a.canonicalFilePath() == b.canonicalFilePath();
}

const char* kForeignGltfLoss =
    QT_TRANSLATE_NOOP("lcui::SceneFiles", "%1 was written by another tool. LightCull writes glTF with geometry, lights "
                                          "and cameras only, so saving over it would lose its materials, textures, "
                                          "animations and anything else it holds: save the scene under a new name.");
} // namespace

bool SceneFiles::save() {
    const bool foreign = isForeignSource(doc_->scene(), doc_->filePath());
    if (doc_->filePath().isEmpty() || foreign) {
        if (foreign) log(tr(kForeignGltfLoss).arg(QFileInfo(doc_->filePath()).fileName()));
        const QString p = prompts_.savePath(
            window_, foreign ? tr("Save scene as a new file (%1 stays as it is)").arg(QFileInfo(doc_->filePath()).fileName())
                          : tr("Save scene"),
            tr("Scene JSON (*.json);;Binary glTF (*.glb);;glTF 2.0 (*.gltf)"));
        return !p.isEmpty() && saveAs(p);
    }
    return saveAs(doc_->filePath());
}

bool SceneFiles::saveAs(const QString& given) {
    // Scene files are told apart by extension (the CLI refuses others): a
    // name typed without one is scene JSON, and gets .json.
    const QString path = QFileInfo(given).suffix().isEmpty() ? given + ".json" : given;
    if (isForeignSource(doc_->scene(), path)) {
        const QString why = tr(kForeignGltfLoss).arg(QFileInfo(path).fileName());
        log(tr("not saved: %1").arg(why), true);
        prompts_.showError(window_, tr("Save scene"), why);
        return false;
    }
    try {
        lc::saveSceneAny(doc_->scene(), path.toStdString()); // .gltf/.glb as glTF, else scene JSON
    } catch (const std::exception& e) {
        log(tr("cannot save %1: %2").arg(path, describe(e)), true);
        prompts_.showError(window_, tr("Save scene"), describe(e));
        return false;
    }
    doc_->markSaved(path);
    addRecentFile(path);
    log(tr("saved %1").arg(path));
    return true;
}

void SceneFiles::addRecentFile(const QString& path) {
    QSettings st;
    QStringList recent = st.value("recentFiles").toStringList();
    const QString abs = QFileInfo(path).absoluteFilePath();
    recent.removeAll(abs);
    recent.prepend(abs);
    while (recent.size() > kMaxRecent) recent.removeLast();
    st.setValue("recentFiles", recent);
    rebuildRecentMenu();
}

void SceneFiles::rebuildRecentMenu() {
    if (!recentMenu_) return;
    recentMenu_->clear();
    const QStringList recent = QSettings().value("recentFiles").toStringList();
    for (const QString& f : recent)
        connect(recentMenu_->addAction(f), &QAction::triggered, this, [this, f] { openSceneFile(f); });
    recentMenu_->setEnabled(!recent.isEmpty());
}

} // namespace lcui
