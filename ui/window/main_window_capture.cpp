// RenderDoc in the studio (issue 36, docs/RENDERDOC.md). File > Open
// RenderDoc capture... reads a renderer's culling dispatch (CaptureDialog)
// and opens its lights and camera as the scene, its lists judged on its depth
// as a built-in run's are: tiles, inspector, Explain and overlays read them.
// Culling > Capture in RenderDoc... writes a capture of the tool's own passes
// by running `lightcull run --renderdoc-capture` on the scene: a process that
// captures must not be the one whose device the studio keeps (RenderDoc hooks
// a device when it is created), and a capture that fails takes only it down.
#include "window/main_window.hpp"

#include "document/document.hpp"
#include "document/run_state.hpp"
#include "panels/capture_dialog.hpp"
#include "widgets/count_text.hpp"
#include "work/cull_worker.hpp"
#include "work/custom_shader_source.hpp"
#include "work/progress_task.hpp"

#include "culling/core/errors.hpp"
#include "culling/scene/scene_io.hpp"

#include <QAction>
#include <QCoreApplication>
#include <QDir>
#include <QFileInfo>
#include <QProcess>
#include <QSettings>
#include <QStatusBar>
#include <QTemporaryDir>

namespace lcui {

namespace {

// The `lightcull` command installed beside the studio (the build tree keeps
// it in ../cli); LIGHTCULL_CLI names another.
QString cliPath() {
    const QString env = qEnvironmentVariable("LIGHTCULL_CLI");
    if (!env.isEmpty()) return env;
    const QDir here(QCoreApplication::applicationDirPath());
    for (const QString& p : {here.filePath("lightcull"), here.filePath("../cli/lightcull")})
        if (QFileInfo(p).isExecutable()) return QFileInfo(p).canonicalFilePath();
    return {};
}

} // namespace

void MainWindow::openCaptureFromDialog() {
    QSettings st;
    CaptureDialog dlg(
        prompts,
        [this](const QString& label, const std::function<void()>& work) {
            runWithProgress(statusProgress_, label, [&](const lc::CancelToken&, const lc::Progress&) { work(); });
        },
        this);
    dlg.setDescription(st.value("capture/description").toString());
    if (prompts.execDialog(dlg) != QDialog::Accepted || !dlg.frame()) return;
    st.setValue("capture/description", dlg.descriptionPath());
    openCaptureFrame(dlg.frame());
}

bool MainWindow::openCapture(const QString& capture, const QString& dispatch, const QString& description) {
    std::shared_ptr<lc::CaptureFrame> frame;
    try {
        runWithProgress(statusProgress_, tr("Reading %1...").arg(QFileInfo(capture).fileName()),
                        [&](const lc::CancelToken&, const lc::Progress&) {
                            frame = std::make_shared<lc::CaptureFrame>(lc::loadCaptureFrame(
                                capture.toStdString(), dispatch.toStdString(),
                                lc::loadCaptureDescription(description.toStdString())));
                        });
    } catch (const std::exception& e) {
        log(tr("cannot open %1: %2").arg(capture, QString::fromStdString(e.what())), true);
        prompts.showError(this, tr("Open RenderDoc capture"), QString::fromStdString(e.what()));
        return false;
    }
    return openCaptureFrame(frame);
}

bool MainWindow::openCaptureFrame(std::shared_ptr<const lc::CaptureFrame> frame) {
    if (!frame || !maybeSave()) return false;
    customShader_->set({}); // the capture's lists are the run's now
    {
        // sceneReset forgets a capture: not this one.
        openingCapture_ = true;
        lc::Scene scene = frame->scene;
        scene.name = QFileInfo(QString::fromStdString(frame->source)).fileName().toStdString();
        capture_ = frame;
        captureLists_ = true;
        doc_->resetScene(std::move(scene), {});
        openingCapture_ = false;
    }
    actions_.captureLists->setEnabled(true);
    for (const std::string& l : frame->echo) log(tr("read %1").arg(QString::fromStdString(l)));
    for (const std::string& w : frame->warnings) warn(QString::fromStdString(w));
    log(tr("opened RenderDoc capture %1: %2, lists %3; the lists are the capture's (edits to the lights are "
           "judged against them; Culling > Built-in algorithm culls on the capture's depth)")
            .arg(QString::fromStdString(frame->source))
            .arg(countOf(frame->scene.lights.size(), "light", "lights"))
            .arg(QString::fromStdString(frame->layoutName)));
    if (runOnOpen && !isLive()) runCulling();
    return true;
}

void MainWindow::forgetCapture() {
    capture_.reset();
    captureLists_ = false;
    actions_.captureLists->setEnabled(false);
}

void MainWindow::setCaptureLists(bool on) {
    if (!capture_) return;
    if (on) customShader_->set({});
    captureLists_ = on;
    log(on ? tr("culling: the capture's lists (%1)").arg(QString::fromStdString(capture_->source))
           : tr("culling: the built-in algorithm on the capture's depth"));
    runCulling();
}

bool MainWindow::captureInRenderDoc(const QString& rdcPath) {
    auto refuse = [this](const QString& why) {
        log(tr("Capture in RenderDoc: %1").arg(why), true);
        prompts.showError(this, tr("Capture in RenderDoc"), why);
        return false;
    };
    if (capture_)
        return refuse(tr("the scene is a RenderDoc capture's (%1): its depth and lists are the renderer's, not the "
                         "tool's passes; open a scene with meshes to capture the tool's culling")
                          .arg(QString::fromStdString(capture_->source)));
    const QString cli = cliPath();
    if (cli.isEmpty())
        return refuse(tr("the lightcull command is not beside the studio (%1); set LIGHTCULL_CLI to it")
                          .arg(QCoreApplication::applicationDirPath()));
    QTemporaryDir tmp;
    if (!tmp.isValid()) return refuse(tr("cannot make a temporary folder: %1").arg(tmp.errorString()));
    const QString scenePath = tmp.filePath("scene.json");
    try {
        lc::saveSceneFile(doc_->scene(), scenePath.toStdString());
    } catch (const std::exception& e) {
        return refuse(QString::fromStdString(e.what()));
    }
    // The run the window would make: its settings or its custom shader, on
    // Vulkan (what RenderDoc captures), on the window's device.
    QStringList args{"run", "--scene", scenePath, "--backend", "vulkan", "--no-image-error",
                     "--out", tmp.filePath("run"), "--renderdoc-capture", QFileInfo(rdcPath).absoluteFilePath()};
    if (!doc_->runs().device().isEmpty()) args << "--device" << doc_->runs().device();
    if (const auto shader = customShader_->options()) {
        args << "--shader" << QString::fromStdString(shader->path) << "--layout"
             << QString::fromStdString(lc::toString(shader->layout)) << "--lists"
             << QString::fromStdString(lc::toString(shader->lists));
        if (!shader->validation) args << "--no-validation";
    } else {
        lc::Camera scratch;
        for (const lc::ParamSpec& p : lc::cullParams())
            if (p.name != "tile" && p.name != "width" && p.name != "height")
                args << "--" + QString::fromStdString(p.name)
                     << QString::fromStdString(lc::getParam(doc_->runs().settings(), scratch, p.name));
    }
    int exitCode = -1;
    QString out, err;
    try {
        runWithProgress(statusProgress_, tr("Capturing in RenderDoc..."),
                        [&](const lc::CancelToken& cancel, const lc::Progress&) {
                            QProcess p;
                            p.start(cli, args);
                            if (!p.waitForStarted(10000)) throw lc::Error("cannot start " + cli.toStdString());
                            while (!p.waitForFinished(100))
                                if (cancel.cancelled) {
                                    p.kill();
                                    p.waitForFinished(5000);
                                    throw lc::Cancelled();
                                }
                            exitCode = p.exitStatus() == QProcess::NormalExit ? p.exitCode() : -1;
                            out = QString::fromLocal8Bit(p.readAllStandardOutput());
                            err = QString::fromLocal8Bit(p.readAllStandardError());
                        });
    } catch (const lc::Cancelled&) {
        log(tr("Capture in RenderDoc cancelled"));
        return false;
    } catch (const std::exception& e) {
        return refuse(QString::fromStdString(e.what()));
    }
    // Exit 3: the run found misses; its capture was written all the same.
    if (exitCode != 0 && exitCode != 3) {
        QString why = err.trimmed();
        if (why.isEmpty()) why = tr("lightcull run ended with exit status %1").arg(exitCode);
        why.replace(QString("lightcull: "), QString());
        return refuse(why.section('\n', 0, 0));
    }
    log(tr("wrote RenderDoc capture %1 (%2 KiB) of the tool's depth pre-pass and culling: open it in RenderDoc "
           "(qrenderdoc %1), or here with File > Open RenderDoc capture...")
            .arg(QFileInfo(rdcPath).absoluteFilePath())
            .arg(QFileInfo(rdcPath).size() / 1024));
    statusBar()->showMessage(tr("wrote %1").arg(rdcPath), 8000);
    return true;
}

} // namespace lcui
