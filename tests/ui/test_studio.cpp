// UI tests of the studio under Xvfb: the document, its undo stack, the worker
// and the panels, driven through the same code paths a user's mouse takes.
// Backend "cpu" keeps them deterministic and fast; 320x180 keeps runs short.

#include "studio_test_support.hpp"

#include "views/camera_view.hpp"
#include "work/cull_worker.hpp"
#include "document/document.hpp"
#include "views/inspector_view.hpp"
#include "window/main_window.hpp"
#include "culling/diagnostics/overlays.hpp"
#include "panels/property_panel.hpp"
#include "panels/scene_tree.hpp"
#include "panels/tile_inspector.hpp"

#include "culling/truth/ground_truth.hpp"
#include "culling/core/pipeline.hpp"
#include "culling/math/projection.hpp"
#include "culling/scene/scene_io.hpp"

#include <vtkScalarBarActor.h>

#include <QAction>
#include <set>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QFile>
#include <QItemSelectionModel>
#include <QLabel>
#include <QLineEdit>
#include <QMessageBox>
#include <QPlainTextEdit>
#include <QProcess>
#include <QSettings>
#include <QProcessEnvironment>
#include <QSet>
#include <QSpinBox>
#include <QStatusBar>
#include <QTabBar>
#include <QImage>
#include <QPushButton>
#include <QRegularExpression>
#include <QTimer>
#include <QWindow>
#include <QUndoStack>
#include <QWheelEvent>

#include <nlohmann/json.hpp>
#include <vtkAlgorithm.h>
#include <vtkCommand.h>
#include <vtkHandleWidget.h>
#include <vtkMapper.h>
#include <vtkPointHandleRepresentation3D.h>
#include <vtkPolyData.h>
#include <vtkActor.h>
#include <vtkRenderer.h>
#include <vtkRenderWindow.h>
#include <vtkProperty.h>
#include <vtkInteractorObserver.h>
#include <vtkRenderWindowInteractor.h>
#include <QVTKInteractor.h>
#include <QElapsedTimer>
#include <QFileInfo>
#include <QMimeData>
#include <QToolBar>
#include <QToolButton>
#include <QUrl>

#include <fstream>
#include <memory>
#include <sstream>

using namespace lcui;

namespace {


std::string sceneText(const Document* d) { return lc::serializeScene(d->scene()); }

double labelNumber(MainWindow* w, const char* name, int which = 0) {
    auto* l = w->findChild<QLabel*>(name);
    if (!l) return -1e300;
    QRegularExpression re("[-+]?[0-9]*\\.?[0-9]+");
    auto it = re.globalMatch(l->text());
    for (int i = 0; it.hasNext(); ++i) {
        const auto m = it.next();
        if (i == which) return m.captured().toDouble();
    }
    return -1e300;
}

} // namespace

class StudioTest : public QObject {
    Q_OBJECT

    std::unique_ptr<MainWindow> w_;
    QTemporaryDir tmp_;

    Document* doc() { return w_->document(); }

    // Waits for the run with `generation` (or a newer one) to be shown.
    bool waitRun(quint64 generation) { return lctest::waitRun(*w_, generation); }

    // Opens the built-in scene at 320x180 on the CPU backend and waits for its run.
    void openSmall(const QString& builtin = "atrium") {
        QVERIFY(lctest::openBuiltinWith(*w_, builtin, {{"width", "320"}, {"height", "180"}}));
        QVERIFY(waitRun(w_->runCulling()));
    }

private slots:
    void init() {
        w_ = lctest::makeTestWindow();
        QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
    }

    void cleanup() {
        doc()->undoStack()->setClean(); // no prompt on close
        w_.reset();
    }

    void opensBuiltinAndSelectsLightInTree() {
        openSmall();
        QVERIFY(doc()->scene().lights.size() > 10);
        SceneTree* tree = w_->sceneTree();
        const QModelIndex idx = tree->lightIndex(3);
        QVERIFY(idx.isValid());
        tree->setCurrentIndex(idx); // what a click on the row does
        QCOMPARE(doc()->selection().selectedLights(), std::vector<int>{3});
        QCOMPARE(doc()->selection().currentLight(), 3);
        auto* name = w_->propertyPanel()->findChild<QLineEdit*>("lightName");
        QCOMPARE(name->text().toStdString(), doc()->scene().lights[3].name);
        // The drag handle sits on the selected light.
        QVERIFY(w_->inspectorView()->handleWidget()->GetEnabled());
        double p[3];
        w_->inspectorView()->handleRepresentation()->GetWorldPosition(p);
        const auto& lp = doc()->scene().lights[3].position;
        QVERIFY(std::abs(p[0] - lp.x) < 1e-9 && std::abs(p[1] - lp.y) < 1e-9 && std::abs(p[2] - lp.z) < 1e-9);
        // Multi-select in the tree selects several lights.
        tree->selectionModel()->select(tree->lightIndex(5), QItemSelectionModel::Select);
        QCOMPARE(doc()->selection().selectedLights().size(), std::size_t(2));
    }

    void dragMovesLightAsOneUndoStep() {
        openSmall();
        doc()->selection().setSelectedLights({2});
        const glm::dvec3 start = doc()->scene().lights[2].position;
        vtkHandleWidget* handle = w_->inspectorView()->handleWidget();
        vtkPointHandleRepresentation3D* rep = w_->inspectorView()->handleRepresentation();
        const int before = doc()->undoStack()->count();
        // The widget's own event sequence during a mouse drag.
        handle->InvokeEvent(vtkCommand::StartInteractionEvent);
        glm::dvec3 p = start;
        for (int i = 1; i <= 5; ++i) {
            p = start + glm::dvec3(0.3 * i, 0.1 * i, -0.2 * i);
            double wp[3] = {p.x, p.y, p.z};
            rep->SetWorldPosition(wp);
            handle->InvokeEvent(vtkCommand::InteractionEvent);
            QCOMPARE(doc()->scene().lights[2].position, p); // the light follows during the drag
        }
        handle->InvokeEvent(vtkCommand::EndInteractionEvent);
        QCOMPARE(doc()->undoStack()->count(), before + 1); // one step for the whole drag
        QVERIFY(doc()->isDirty());
        // The glyph input (what the view draws) moved too.
        auto* glyphInput = vtkPolyData::SafeDownCast(
            w_->inspectorView()->lightActor()->GetMapper()->GetInputAlgorithm()->GetInputDataObject(0, 0));
        QVERIFY(glyphInput);
        double gp[3];
        glyphInput->GetPoint(2, gp);
        QVERIFY(std::abs(gp[0] - p.x) < 1e-9 && std::abs(gp[2] - p.z) < 1e-9);

        doc()->undoStack()->undo();
        QCOMPARE(doc()->scene().lights[2].position, start);
        doc()->undoStack()->redo();
        QCOMPARE(doc()->scene().lights[2].position, p);
        // A second drag is a second step.
        handle->InvokeEvent(vtkCommand::StartInteractionEvent);
        double wp[3] = {start.x, start.y, start.z};
        rep->SetWorldPosition(wp);
        handle->InvokeEvent(vtkCommand::InteractionEvent);
        handle->InvokeEvent(vtkCommand::EndInteractionEvent);
        QCOMPARE(doc()->undoStack()->count(), before + 2);
    }

    void dragSphereSetsRadiusAsOneUndoStep() {
        openSmall();
        doc()->selection().setSelectedLights({6});
        const lc::PointLight before = doc()->scene().lights[6];
        vtkHandleWidget* handle = w_->inspectorView()->radiusHandleWidget();
        vtkPointHandleRepresentation3D* rep = w_->inspectorView()->radiusHandleRepresentation();
        QVERIFY(handle->GetEnabled());
        double wp[3];
        rep->GetWorldPosition(wp);
        // The handle starts on the sphere.
        QVERIFY(std::abs(glm::length(glm::dvec3(wp[0], wp[1], wp[2]) - before.position) - before.radius()) < 1e-9);
        const int count = doc()->undoStack()->count();
        handle->InvokeEvent(vtkCommand::StartInteractionEvent);
        for (double r : {1.5, 2.0, 2.5}) {
            const glm::dvec3 p = before.position + glm::dvec3(0, r, 0);
            double q[3] = {p.x, p.y, p.z};
            rep->SetWorldPosition(q);
            handle->InvokeEvent(vtkCommand::InteractionEvent);
        }
        handle->InvokeEvent(vtkCommand::EndInteractionEvent);
        QCOMPARE(doc()->scene().lights[6].radius(), 2.5);
        QCOMPARE(doc()->scene().lights[6].position, before.position);
        QCOMPARE(doc()->undoStack()->count(), count + 1);
        doc()->undoStack()->undo();
        QCOMPARE(doc()->scene().lights[6].explicitRadius, before.explicitRadius);
        QCOMPARE(doc()->scene().lights[6].radius(), before.radius());
    }

    void runMatchesCli() {
        openSmall();
        const auto run = doc()->runs().runOutput();
        QVERIFY(run);
        QCOMPARE(QString::fromStdString(run->result.backend), QString("cpu"));
        QCOMPARE(run->result.grid.width, 320u);

        const QString out = tmp_.path() + "/cli";
        QProcess cli;
        cli.start(LC_CLI_PATH, {"run", "--builtin", "atrium", "--width", "320", "--height", "180", "--tile",
                                "16", "--algorithm", "2.5d", "--cells", "32", "--slicing", "log", "--test",
                                "planes", "--backend", "cpu", "--no-image-error", "--out", out});
        QVERIFY(cli.waitForFinished(lctest::kRunTimeoutMs));
        QVERIFY2(cli.exitCode() == 0, cli.readAllStandardError().constData());
        std::ifstream sf((out + "/summary.json").toStdString());
        const auto summary = nlohmann::json::parse(sf);
        const auto& m = summary["metrics"];

        // Status bar figures, as shown (FN exact, efficiency to 4 decimals,
        // mean list to 2, max exact).
        QCOMPARE(labelNumber(w_.get(), "statusFalseNegatives"), double(m["false_negatives"].get<std::uint64_t>()));
        QVERIFY(std::abs(labelNumber(w_.get(), "statusEfficiency") - m["efficiency"].get<double>()) < 0.6e-4);
        QVERIFY(std::abs(labelNumber(w_.get(), "statusLists", 0) - m["mean_list"].get<double>()) < 0.006);
        QCOMPARE(labelNumber(w_.get(), "statusLists", 1), double(m["max_list"].get<int>()));
        QVERIFY(w_->findChild<QLabel*>("statusBackend")->text().startsWith("cpu"));

        // The tile with the longest list in tiles.csv, picked by a click in the camera view.
        QFile csv(out + "/tiles.csv");
        QVERIFY(csv.open(QIODevice::ReadOnly));
        csv.readLine();
        int bestX = -1, bestY = -1, bestCount = -1;
        std::vector<int> bestLights;
        while (!csv.atEnd()) {
            const QStringList f = QString::fromUtf8(csv.readLine()).trimmed().split(',');
            QCOMPARE(f.size(), 13);
            if (f[6].toInt() > bestCount) {
                bestCount = f[6].toInt();
                bestX = f[0].toInt();
                bestY = f[1].toInt();
                bestLights.clear();
                for (const QString& s : f[12].split(' ', Qt::SkipEmptyParts)) bestLights.push_back(s.toInt());
            }
        }
        QVERIFY(bestCount > 0);
        CameraView* cv = w_->cameraView();
        cv->renderNow();
        const double* vp = cv->sceneRenderer()->GetViewport();
        const double u = (bestX * 16 + 8) / 320.0, v = (bestY * 16 + 8) / 180.0; // tile centre, image fraction
        const QPoint click(int((vp[0] + u * (vp[2] - vp[0])) * cv->width()),
                           int((1.0 - (vp[3] - v * (vp[3] - vp[1]))) * cv->height()));
        QTest::mouseClick(cv, Qt::LeftButton, {}, click);
        QTRY_COMPARE(doc()->selection().selectedTile(), bestY * 20 + bestX);
        QCOMPARE(w_->tileInspector()->listedLights(), bestLights);
    }

    // The VTK camera of the camera view must see exactly what the culling
    // camera saw: a world point lands on the same pixel of the letterboxed
    // viewport as lc::Projection puts it, for perspective and orthographic.
    void cameraViewMatchesCullingCamera() {
        openSmall();
        CameraView* cv = w_->cameraView();
        for (auto kind : {lc::ProjectionKind::Perspective, lc::ProjectionKind::Orthographic}) {
            lc::Camera cam = doc()->scene().camera;
            cam.projection = kind;
            doc()->setCamera(cam);
            cv->renderNow();
            const lc::Projection proj(cam);
            const glm::dmat4 view = cam.viewFromWorld();
            vtkRenderer* ren = cv->sceneRenderer();
            const double* vp = ren->GetViewport();
            int checked = 0;
            for (const auto& l : doc()->scene().lights) {
                const glm::dvec3 pv = glm::dvec3(view * glm::dvec4(l.position, 1.0));
                if (-pv.z <= cam.nearPlane) continue;
                const glm::dvec2 px = proj.pixelFromView(pv);
                if (px.x < 0 || px.y < 0 || px.x > cam.width || px.y > cam.height) continue;
                ren->SetWorldPoint(l.position.x, l.position.y, l.position.z, 1.0);
                ren->WorldToDisplay();
                double d[3];
                ren->GetDisplayPoint(d);
                // Display (y up) -> culling pixel (y down) through the viewport.
                const int* size = cv->renderWindow()->GetSize();
                const double u = (d[0] / size[0] - vp[0]) / (vp[2] - vp[0]);
                const double v = (d[1] / size[1] - vp[1]) / (vp[3] - vp[1]);
                const glm::dvec2 got(u * cam.width, (1.0 - v) * cam.height);
                QVERIFY2(glm::length(got - px) < 0.05 * cam.height / 10,
                         qPrintable(QString("%1: vtk (%2, %3) vs culling (%4, %5)")
                                        .arg(lc::toString(kind)).arg(got.x).arg(got.y).arg(px.x).arg(px.y)));
                if (++checked == 20) break;
            }
            QVERIFY(checked > 0);
            // Clicking on a pixel selects the tile that holds it.
            // (a fraction of the image well inside a tile, not on a tile border)
            const QPoint click(int(cv->width() * (vp[0] + 0.33 * (vp[2] - vp[0]))),
                               int(cv->height() * (1 - (vp[1] + 0.67 * (vp[3] - vp[1])))));
            const int expected = int(lc::TileGrid::make(cam.width, cam.height, cam.tileSize)
                                         .tileOfPixel(std::uint32_t(0.33 * cam.width), std::uint32_t(0.33 * cam.height)));
            QCOMPARE(cv->tileAtWidgetPos(click), expected);
        }
    }

    void backendSwitchAndBadBackend() {
        openSmall();
        QVERIFY(lctest::waitRun(*w_, doc()->runs().runGeneration(), true)); // with its ground truth
        const auto cpu = doc()->runs().runOutput();
        QCOMPARE(QString::fromStdString(cpu->result.backend), QString("cpu"));
        const auto names = lc::availableBackends();
        // The switch is this test's point: lavapipe is part of the stack
        // (DESIGN.md), so a missing Vulkan device fails rather than skips.
        QVERIFY2(std::find(names.begin(), names.end(), "vulkan") != names.end(), "no Vulkan device to switch to");
        // The worker recreates its backend and runs the same scene on it.
        w_->setBackend("vulkan");
        QVERIFY(lctest::waitRun(*w_, w_->runCulling(), true));
        const auto vk = doc()->runs().runOutput();
        QCOMPARE(QString::fromStdString(vk->result.backend), QString("vulkan"));
        QVERIFY(w_->findChild<QLabel*>("statusBackend")->text().startsWith("vulkan"));
        // The two backends' lists. They are not identical by design
        // (docs/TESTING.md, "Hard cases"): each runs its own depth pre-pass
        // (lavapipe and the CPU rasteriser round edge pixels differently) and
        // the GPU widens its tests by float rounding, so its lists are a
        // superset of the CPU reference's on the same depth, with at most
        // 8 + 0.5% extra entries. So: the same grid and list layout, no false
        // negatives on either, and the Vulkan lists against the CPU
        // reference culled on the Vulkan run's own depth.
        QCOMPARE(vk->result.grid.tilesX, cpu->result.grid.tilesX);
        QCOMPARE(vk->result.grid.tilesY, cpu->result.grid.tilesY);
        QCOMPARE(vk->result.listsPerTile, cpu->result.listsPerTile);
        QCOMPARE(vk->result.listCount.size(), cpu->result.listCount.size());
        QCOMPARE(vk->result.listOffset.size(), cpu->result.listOffset.size());
        QVERIFY(vk->truthComputed && cpu->truthComputed);
        QCOMPARE(cpu->truth.metrics.falseNegatives, std::uint64_t(0));
        QCOMPARE(vk->truth.metrics.falseNegatives, std::uint64_t(0));
        QVERIFY(cpu->truth.metrics.exactWork > 0); // lights reach the geometry: FN = 0 says something
        {
            const lc::Projection proj(doc()->scene().camera);
            auto cpuBackend = lc::makeBackend("cpu");
            const lc::CullResult ref =
                cpuBackend->cull(vk->depth, proj, vk->result.grid, vk->lights, doc()->runs().settings());
            QCOMPARE(ref.listCount.size(), vk->result.listCount.size());
            std::uint64_t extra = 0, lacking = 0;
            for (std::size_t l = 0; l < ref.listCount.size(); ++l) {
                const auto rb = ref.lightIndices.begin() + ref.listOffset[l], re = rb + ref.listCount[l];
                const auto vb = vk->result.lightIndices.begin() + vk->result.listOffset[l],
                           ve = vb + vk->result.listCount[l];
                std::vector<std::uint32_t> lost;
                std::set_difference(rb, re, vb, ve, std::back_inserter(lost));
                lacking += lost.size();
                extra += vk->result.listCount[l] - (ref.listCount[l] - lost.size());
            }
            QCOMPARE(lacking, std::uint64_t(0));
            QVERIFY2(extra <= 8 + ref.entries() / 200,
                     qPrintable(QString("%1 extra Vulkan entries over %2").arg(extra).arg(ref.entries())));
        }
        // Back on cpu: exactly the lists of the first cpu run, entry for entry.
        w_->setBackend("cpu");
        QVERIFY(lctest::waitRun(*w_, w_->runCulling(), true));
        const auto cpuAgain = doc()->runs().runOutput();
        QCOMPARE(QString::fromStdString(cpuAgain->result.backend), QString("cpu"));
        QVERIFY(cpuAgain != cpu); // a new run, not the old one shown again
        QVERIFY(cpuAgain->result.listOffset == cpu->result.listOffset);
        QVERIFY(cpuAgain->result.listCount == cpu->result.listCount);
        QVERIFY(cpuAgain->result.lightIndices == cpu->result.lightIndices);
        QCOMPARE(cpuAgain->truth.metrics.shadingWork, cpu->truth.metrics.shadingWork);

        // An unknown backend is an error in the log; the last result stays.
        w_->setBackend("cpu", "");
        QSignalSpy failed(w_.get(), &MainWindow::runFailed);
        const quint64 shown = doc()->runs().runGeneration();
        w_->cullService()->request(doc()->scene(), doc()->runs().settings(), "no-such-backend", "");
        QVERIFY(failed.wait(lctest::kRunTimeoutMs));
        QCOMPARE(doc()->runs().runGeneration(), shown);
        QVERIFY(w_->messageLog()->toPlainText().contains("no-such-backend"));
        QVERIFY(waitRun(w_->runCulling())); // and cpu works again
        QCOMPARE(QString::fromStdString(doc()->runs().runOutput()->result.backend), QString("cpu"));
    }

    void undoRedoEveryEditKind() {
        openSmall();
        QUndoStack* undo = doc()->undoStack();
        auto check = [&](const char* what, const std::function<void()>& edit) {
            const std::string before = sceneText(doc());
            const int count = undo->count();
            edit();
            const std::string after = sceneText(doc());
            QVERIFY2(after != before, what);
            QVERIFY2(undo->count() == count + 1, what);
            undo->undo();
            QVERIFY2(sceneText(doc()) == before, what);
            undo->redo();
            QVERIFY2(sceneText(doc()) == after, what);
        };
        check("move", [&] { doc()->moveLight(0, doc()->scene().lights[0].position + glm::dvec3(1, 0, 0), doc()->newDragId()); });
        check("property", [&] {
            doc()->selection().setSelectedLights({1});
            auto* spin = w_->propertyPanel()->findChild<QDoubleSpinBox*>("lightIntensity");
            spin->setValue(spin->value() + 2.5);
        });
        check("colour", [&] {
            doc()->selection().setSelectedLights({1});
            w_->propertyPanel()->pickColor = [](QWidget*, QColor) { return QColor(255, 0, 0); };
            w_->propertyPanel()->findChild<QPushButton*>("lightColor")->click();
            QCOMPARE(doc()->scene().lights[1].color, glm::dvec3(1, 0, 0));
        });
        check("add", [&] { w_->addLightAtCentre(); });
        check("duplicate", [&] {
            doc()->selection().setSelectedLights({0, 4});
            w_->action("actionDuplicate")->trigger();
        });
        check("delete", [&] {
            doc()->selection().setSelectedLights({1, 3, 7});
            const std::string l2 = doc()->scene().lights[2].name;
            w_->action("actionDelete")->trigger();
            QCOMPARE(doc()->scene().lights[1].name, l2);
        });
        check("generate", [&] {
            const std::size_t n = doc()->scene().lights.size();
            QVERIFY(w_->generateLights(lc::defaultLightGen(doc()->scene(), 1000, 7)));
            QCOMPARE(doc()->scene().lights.size(), n + 1000);
        });
        check("camera", [&] {
            doc()->selection().selectCamera();
            auto* fov = w_->propertyPanel()->findChild<QDoubleSpinBox*>("cameraFov");
            fov->setValue(fov->value() - 10);
        });
        check("camera from view", [&] { w_->setCullingCameraFromInspector(); });
        check("import", [&] {
            QVERIFY(w_->importMeshFile(LC_ASSETS_DIR "/stanford_bunny/bun_zipper.ply"));
        });
    }

    void unsavedChangesPrompt() {
        openSmall();
        doc()->moveLight(0, doc()->scene().lights[0].position + glm::dvec3(0, 1, 0), doc()->newDragId());
        QVERIFY(doc()->isDirty());
        const std::string edited = sceneText(doc());

        // The real prompt: find the modal message box and press Cancel.
        bool seen = false;
        QTimer::singleShot(100, [&] {
            auto* box = qobject_cast<QMessageBox*>(QApplication::activeModalWidget());
            if (!box) return;
            seen = box->text().contains("Save changes");
            box->button(QMessageBox::Cancel)->click();
        });
        QVERIFY(!w_->openBuiltin("wall"));
        QVERIFY(seen);
        QCOMPARE(sceneText(doc()), edited); // cancelled: the edit is still there
        QVERIFY(doc()->isDirty());

        // Closing asks too; Cancel keeps the window open.
        int asked = 0;
        w_->prompts.askUnsaved = [&](QWidget*, const QString&) {
            ++asked;
            return QMessageBox::Cancel;
        };
        QVERIFY(!w_->close());
        QCOMPARE(asked, 1);
        QVERIFY(w_->isVisible());

        // Save: goes through the save path prompt, writes the file, then proceeds.
        const QString path = tmp_.path() + "/saved.json";
        w_->prompts.askUnsaved = [&](QWidget*, const QString&) {
            ++asked;
            return QMessageBox::Save;
        };
        w_->prompts.savePath = [&](QWidget*, const QString&, const QString&) { return path; };
        QVERIFY(w_->newScene());
        QCOMPARE(asked, 2);
        QVERIFY(QFile::exists(path));
        QCOMPARE(lc::serializeScene(lc::loadSceneFile(path.toStdString())), edited);
        QCOMPARE(doc()->scene().lights.size(), std::size_t(0)); // the new, empty scene
        QVERIFY(!doc()->isDirty());

        // Discard: no file written, the other scene opens.
        doc()->addLights({lc::PointLight{}}, "add");
        w_->prompts.askUnsaved = [&](QWidget*, const QString&) {
            ++asked;
            return QMessageBox::Discard;
        };
        QVERIFY(w_->openSceneFile(path));
        QCOMPARE(asked, 3);
        QCOMPARE(sceneText(doc()), edited);
        QCOMPARE(doc()->filePath(), path);

        // A name typed without an extension is saved as scene JSON under .json
        // (what the CLI and Open recognise).
        w_->prompts.savePath = [&](QWidget*, const QString&, const QString&) { return tmp_.path() + "/bare"; };
        w_->action("actionSaveAs")->trigger();
        QVERIFY(QFile::exists(tmp_.path() + "/bare.json"));
        QVERIFY(!QFile::exists(tmp_.path() + "/bare"));
        QCOMPARE(doc()->filePath(), tmp_.path() + "/bare.json");
    }

    // An import that drops degenerate faces went through: the log warns, it
    // does not say ERROR (a user scanning for errors thought it failed).
    void droppedFacesAreAWarningNotAnError() {
        openSmall();
        const QString path = tmp_.path() + "/degenerate.obj";
        QFile f(path);
        QVERIFY(f.open(QIODevice::WriteOnly));
        f.write("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 1 2\n");
        f.close();
        QVERIFY(w_->importMeshFile(path));
        const QString log = w_->messageLog()->toPlainText();
        QVERIFY2(log.contains(QRegularExpression("WARNING .*degenerate.obj: dropped 1 degenerate")), qPrintable(log));
        QVERIFY2(!log.contains("ERROR"), qPrintable(log));
    }

    void failedImportLeavesSceneIntact() {
        openSmall();
        const std::string before = sceneText(doc());
        const int count = doc()->undoStack()->count();
        QStringList errors;
        w_->prompts.showError = [&](QWidget*, const QString&, const QString& m) { errors << m; };

        const QString broken = tmp_.path() + "/broken.obj";
        QFile f(broken);
        QVERIFY(f.open(QIODevice::WriteOnly));
        f.write("v 0 0 0\nv nan 1 0\nv 1 1 0\nf 1 2 3\n");
        f.close();
        QVERIFY(!w_->importMeshFile(broken));
        QVERIFY(!w_->importMeshFile(tmp_.path() + "/does_not_exist.ply"));
        QCOMPARE(errors.size(), 2);
        QCOMPARE(sceneText(doc()), before);
        QCOMPARE(doc()->undoStack()->count(), count);
        const QString log = w_->messageLog()->toPlainText();
        QVERIFY(log.contains("cannot import " + broken));
        QVERIFY(log.contains("does_not_exist.ply"));
        // A failed scene open leaves the scene as it was too.
        QVERIFY(!w_->openSceneFile(broken));
        QCOMPARE(sceneText(doc()), before);
    }

    void cullingErrorIsLoggedAndSceneKept() {
        openSmall();
        lc::PointLight bad = doc()->scene().lights[4];
        bad.minIntensity = 0; // I_min must be > 0
        doc()->setLight(4, bad);
        const std::string before = sceneText(doc());
        QSignalSpy failed(w_.get(), &MainWindow::runFailed);
        w_->runCulling();
        QVERIFY(failed.wait(lctest::kRunTimeoutMs));
        const QString msg = failed.last().at(1).toString();
        QVERIFY2(msg.contains(QString::fromStdString(bad.name)), qPrintable(msg));
        QVERIFY(w_->messageLog()->toPlainText().contains("failed"));
        QCOMPARE(sceneText(doc()), before);
    }

    void newestResultWins() {
        openSmall();
        QSignalSpy finished(w_->cullService(), &CullService::finished);
        quint64 last = 0;
        for (int i = 0; i < 6; ++i) {
            doc()->moveLight(0, doc()->scene().lights[0].position + glm::dvec3(0.1, 0, 0), doc()->newDragId());
            last = w_->runCulling();
        }
        QVERIFY(waitRun(last));
        QCOMPARE(doc()->runs().runGeneration(), last);
        QTest::qWait(100);
        // Every request either ran or was replaced while still queued.
        QCOMPARE(quint64(finished.size()) + w_->cullService()->worker()->droppedRequests(), quint64(6));
        // A late, older result is not shown over the newer one.
        QVERIFY(!doc()->runs().setRunOutput(doc()->runs().runOutput(), last - 1));
        QCOMPARE(doc()->runs().runGeneration(), last);
    }

    void liveModeRerunsAfterEdit() {
        openSmall();
        const quint64 gen = doc()->runs().runGeneration();
        w_->setLive(true);
        QVERIFY(waitRun(gen + 1)); // turning Live on runs once
        const quint64 g2 = doc()->runs().runGeneration();
        doc()->moveLight(0, doc()->scene().lights[0].position + glm::dvec3(0, 0.5, 0), doc()->newDragId());
        QVERIFY(waitRun(g2 + 1));
        QCOMPARE(doc()->runs().runOutput()->lights.centers.size(), doc()->scene().lights.size());
        w_->setLive(false);
    }

    // Run culling and Live are in sight at the window's size (they were at
    // the end of the culling row, behind its overflow button below 1,700 px).
    void runAndLiveButtonsAreInSight() {
        for (const char* name : {"actionRun", "actionLive"}) {
            QWidget* button = nullptr;
            for (QToolBar* bar : w_->findChildren<QToolBar*>())
                if (QWidget* b = bar->widgetForAction(w_->action(name))) button = b;
            QVERIFY2(button && button->isVisible(), name);
            QVERIFY2(w_->rect().contains(button->mapTo(w_.get(), button->rect().center())), name);
        }
    }

    // The log is a strip of a few lines at the bottom; its Report tab grows
    // the strip to a height where the chart reads, and the log tab gives the
    // strip back.
    void theReportTabGetsRoomAndTheLogGivesItBack() {
        auto* logDock = w_->findChild<QDockWidget*>("logDock");
        auto* reportDock = w_->findChild<QDockWidget*>("reportDock");
        QVERIFY(logDock && reportDock);
        QTRY_VERIFY(logDock->isVisible());
        const int strip = logDock->height();
        QVERIFY2(strip < 200, qPrintable(QString::number(strip)));
        QTabBar* tabs = nullptr;
        int reportTab = -1, logTab = -1;
        for (QTabBar* bar : w_->findChildren<QTabBar*>())
            for (int i = 0; i < bar->count(); ++i) {
                if (bar->tabText(i) == "Report") tabs = bar, reportTab = i;
                if (bar->tabText(i) == "Message log") logTab = i;
            }
        QVERIFY(tabs && reportTab >= 0 && logTab >= 0);
        QTest::mouseClick(tabs, Qt::LeftButton, {}, tabs->tabRect(reportTab).center());
        QTRY_VERIFY(reportDock->isVisible());
        QTRY_VERIFY2(reportDock->height() >= 300, qPrintable(QString::number(reportDock->height())));
        QTest::mouseClick(tabs, Qt::LeftButton, {}, tabs->tabRect(logTab).center());
        QTRY_VERIFY(logDock->isVisible());
        QTRY_COMPARE(logDock->height(), strip);
    }

    // Typing the camera's position into its target would make a camera no
    // run can use (and a saved file that does not open): the edit is refused,
    // the field shows the old value and the log says why.
    void anInvalidCameraEditIsRefused() {
        openSmall();
        doc()->selection().selectCamera();
        auto* panel = w_->findChild<PropertyPanel*>();
        QVERIFY(panel);
        QSignalSpy refused(panel, &PropertyPanel::editRefused);
        QList<QDoubleSpinBox*> target;
        for (auto* spin : panel->findChildren<QDoubleSpinBox*>("cameraTarget")) target.push_back(spin);
        QCOMPARE(target.size(), 3);
        const lc::Camera before = doc()->scene().camera;
        // Two axes to the position's; the last one would make them equal.
        int differ = -1;
        for (int i = 0; i < 3; ++i)
            if (before.target[i] != before.position[i]) differ = i;
        QVERIFY(differ >= 0);
        for (int i = 0; i < 3; ++i)
            if (i != differ) target[i]->setValue(before.position[i]);
        QVERIFY(refused.isEmpty());
        const int steps = doc()->undoStack()->count();
        target[differ]->setValue(before.position[differ]);
        QCOMPARE(refused.size(), 1);
        QVERIFY2(refused.at(0).at(0).toString().contains("camera.target") ||
                     refused.at(0).at(0).toString().contains("target"),
                 qPrintable(refused.at(0).at(0).toString()));
        QCOMPARE(doc()->undoStack()->count(), steps);
        QVERIFY(doc()->scene().camera.validate().empty());
        QCOMPARE(target[differ]->value(), before.target[differ]);
    }

    // The heat legend labels whole numbers once each: a scene whose longest
    // list is short gets a label per count, not five rounded repeats.
    void heatLegendLabelsEachCountOnce() {
        for (const char* scene : {"sky", "atrium"}) {
            openSmall(scene);
            double top = 0;
            for (double v : lc::tileHeat(*doc()->runs().runOutput(), lc::HeatMode::ListLength))
                if (!std::isnan(v)) top = std::max(top, v);
            top = std::max(top, 1.0);
            vtkScalarBarActor* legend = w_->cameraView()->legend();
            const int labels = legend->GetNumberOfLabels();
            QCOMPARE(labels, top < 5 ? int(top) + 1 : 5);
            // Evenly spaced over 0..top, as printed ("%.0f"): no two alike.
            QStringList printed;
            for (int k = 0; k < labels; ++k) printed << QString::number(top * k / (labels - 1), 'f', 0);
            QCOMPARE(QSet<QString>(printed.begin(), printed.end()).size(), labels);
        }
    }

    // A small scene's light (the Add spot light of a 10 cm model gets about
    // 0.0004 cd) can be typed in: the field keeps six decimals.
    void smallIntensitiesCanBeTyped() {
        openSmall();
        doc()->selection().setSelectedLights({0});
        auto* panel = w_->findChild<PropertyPanel*>();
        auto* intensity = panel->findChild<QDoubleSpinBox*>("lightIntensity");
        QVERIFY(intensity);
        intensity->setValue(0.0004);
        QCOMPARE(doc()->scene().lights[0].intensity, 0.0004);
    }

    // Lights are found by name: generating beside the scene's own lights
    // numbers on past theirs, and an empty name is refused.
    void lightNamesStayUniqueAndNonEmpty() {
        openSmall();
        const std::size_t before = doc()->scene().lights.size();
        QVERIFY(w_->generateLights(lc::defaultLightGen(doc()->scene(), 30, 3)));
        std::set<std::string> names;
        for (const auto& l : doc()->scene().lights) names.insert(l.name);
        QCOMPARE(names.size(), before + 30);
        doc()->selection().setSelectedLights({0});
        auto* panel = w_->findChild<PropertyPanel*>();
        QSignalSpy refused(panel, &PropertyPanel::editRefused);
        auto* name = panel->findChild<QLineEdit*>("lightName");
        QVERIFY(name);
        const std::string old = doc()->scene().lights[0].name;
        name->clear();
        QTest::keyClick(name, Qt::Key_Return);
        QCOMPARE(refused.size(), 1);
        QCOMPARE(doc()->scene().lights[0].name, old);
        QCOMPARE(name->text(), QString::fromStdString(old));
    }

    // After Enter the focus stays in the field; Ctrl+Z there undoes the
    // scene edit (the field's own text undo took it, and nothing happened).
    void ctrlZInAFieldUndoesTheEdit() {
        openSmall();
        doc()->selection().setSelectedLights({0});
        auto* panel = w_->findChild<PropertyPanel*>();
        auto* intensity = panel->findChild<QDoubleSpinBox*>("lightIntensity");
        const double before = doc()->scene().lights[0].intensity;
        w_->activateWindow();
        QApplication::setActiveWindow(w_.get()); // no window manager under Xvfb gives it
        intensity->setFocus();
        QTRY_VERIFY(intensity->hasFocus());
        intensity->selectAll();
        QTest::keyClicks(intensity, "7.5");
        QTest::keyClick(intensity, Qt::Key_Return);
        QCOMPARE(doc()->scene().lights[0].intensity, 7.5);
        QTest::keyClick(intensity, Qt::Key_Z, Qt::ControlModifier);
        QCOMPARE(doc()->scene().lights[0].intensity, before);
        QTest::keyClick(intensity, Qt::Key_Z, Qt::ControlModifier | Qt::ShiftModifier);
        QCOMPARE(doc()->scene().lights[0].intensity, 7.5);

        // The culling toolbar's tile size is a camera edit: Ctrl+Z there too.
        auto* tile = w_->findChild<QSpinBox*>("param_tile");
        QVERIFY(tile);
        const std::uint32_t tileBefore = doc()->scene().camera.tileSize;
        tile->setFocus();
        QTRY_VERIFY(tile->hasFocus());
        tile->selectAll();
        QTest::keyClicks(tile, "64");
        QTest::keyClick(tile, Qt::Key_Return);
        QCOMPARE(doc()->scene().camera.tileSize, 64u);
        QTest::keyClick(tile, Qt::Key_Z, Qt::ControlModifier);
        QCOMPARE(doc()->scene().camera.tileSize, tileBefore);
        QCOMPARE(tile->value(), int(tileBefore));
        QTest::keyClick(tile, Qt::Key_Z, Qt::ControlModifier | Qt::ShiftModifier);
        QCOMPARE(doc()->scene().camera.tileSize, 64u);
    }

    // The wheel over the properties scrolls them; it edits a field only once
    // the user has put the focus there (wheeling past Min intensity set it to
    // 1e-6 and the radius to 2 km).
    void theWheelScrollsThePropertiesUntilAFieldHasFocus() {
        openSmall();
        doc()->selection().setSelectedLights({0});
        auto* panel = w_->findChild<PropertyPanel*>();
        auto* minIntensity = panel->findChild<QDoubleSpinBox*>("lightMinIntensity");
        QVERIFY(minIntensity);
        const std::string before = sceneText(doc());
        const int steps = doc()->undoStack()->count();
        auto wheel = [&](QWidget* target) {
            const QPoint at = target->rect().center();
            QWheelEvent e(at, target->mapToGlobal(at), QPoint(), QPoint(0, -120), Qt::NoButton, Qt::NoModifier,
                          Qt::NoScrollPhase, false);
            QApplication::sendEvent(target, &e);
        };
        minIntensity->clearFocus();
        for (int i = 0; i < 5; ++i) wheel(minIntensity);
        QCOMPARE(sceneText(doc()), before);
        QCOMPARE(doc()->undoStack()->count(), steps);
        // Focused, the wheel is the field's again.
        QApplication::setActiveWindow(w_.get());
        minIntensity->setFocus();
        QTRY_VERIFY(minIntensity->hasFocus());
        const double value = minIntensity->value();
        wheel(minIntensity);
        QVERIFY(minIntensity->value() != value);
    }

    // The keys docs/STUDIO.md lists reach their actions on any platform
    // theme (QKeySequence::SaveAs and ::Quit are empty under some, Xvfb's).
    void documentedShortcutsAreBound() {
        const std::pair<const char*, const char*> keys[] = {
            {"actionNew", "Ctrl+N"},      {"actionOpen", "Ctrl+O"},         {"actionImport", "Ctrl+I"},
            {"actionSave", "Ctrl+S"},     {"actionSaveAs", "Ctrl+Shift+S"}, {"actionExportDiagnostics", "Ctrl+E"},
            {"actionQuit", "Ctrl+Q"},     {"actionUndo", "Ctrl+Z"},         {"actionRedo", "Ctrl+Shift+Z"},
            {"actionDuplicate", "Ctrl+D"}, {"actionGenerate", "Ctrl+G"},   {"actionRun", "F5"},
            {"actionNextMiss", "F8"},     {"actionPreviousMiss", "Shift+F8"}};
        for (const auto& [name, key] : keys) {
            QAction* a = w_->action(name);
            QVERIFY2(a, name);
            QVERIFY2(a->shortcuts().contains(QKeySequence(key)), qPrintable(QString("%1: %2").arg(name, key)));
        }
    }

    // Opening a scene with Live on runs it once, with its own depth pass (a
    // second run over the first one's depth showed "depth reused").
    void openingWithLiveOnRunsOnce() {
        openSmall();
        w_->setLive(true);
        w_->runOnOpen = true;
        const quint64 before = w_->runCulling();
        QVERIFY(w_->openBuiltin("sky"));
        const quint64 after = w_->runCulling();
        QCOMPARE(after, before + 2);
        QVERIFY(waitRun(after));
        w_->runOnOpen = false;
        w_->setLive(false);
    }

    // A light move re-culls over the previous depth image (the pre-pass is
    // skipped and the status bar says so); a camera edit renders depth again.
    void liveLightMoveReusesDepthCameraEditDoesNot() {
        openSmall();
        const quint64 gen = doc()->runs().runGeneration();
        QVERIFY(!doc()->runs().runOutput()->depthReused);
        // The run that rendered depth says how many triangles it drew (the CPU
        // rasteriser: all), in its result and in the message log.
        const std::size_t triangles = doc()->scene().triangleCount();
        QCOMPARE(doc()->runs().runOutput()->result.depthTriangles, triangles);
        QCOMPARE(doc()->runs().runOutput()->result.depthTrianglesDrawn, triangles);
        QVERIFY(w_->messageLog()->toPlainText().contains(QString("(%1 of %1 triangles)").arg(triangles)));
        w_->setLive(true);
        QVERIFY(waitRun(gen + 1));
        const std::vector<float> depth = doc()->runs().runOutput()->depth.depth;
        doc()->moveLight(1, doc()->scene().lights[1].position + glm::dvec3(0.5, 0, 0), doc()->newDragId());
        QVERIFY(waitRun(gen + 2));
        QVERIFY(doc()->runs().runOutput()->depthReused);
        QCOMPARE(doc()->runs().runOutput()->result.depthTriangles, std::size_t(0));
        QVERIFY(doc()->runs().runOutput()->depth.depth == depth);
        bool saysReused = false;
        for (QLabel* l : w_->statusBar()->findChildren<QLabel*>())
            saysReused = saysReused || l->text().startsWith("depth reused");
        QVERIFY(saysReused);
        // The log says so too (not "depth 0.00 ms"), once the truth is in, and
        // the run knows whose depth it culled against (summary.json's depth_source).
        QTRY_VERIFY(doc()->runs().runOutput()->truthComputed);
        const QString log = w_->messageLog()->toPlainText();
        const QString last = log.section('\n', -1);
        QVERIFY2(last.contains("depth reused (camera and meshes unchanged)"), qPrintable(last));
        QVERIFY2(QString::fromStdString(doc()->runs().runOutput()->depthFrom)
                     .startsWith("the previous run's pre-pass on cpu ("),
                 doc()->runs().runOutput()->depthFrom.c_str());
        QVERIFY(QString::fromStdString(doc()->runs().runOutput()->depthFrom).endsWith("(camera and meshes unchanged)"));

        lc::Camera c = doc()->scene().camera;
        c.position += glm::dvec3(0.0, 0.5, 0.0);
        doc()->setCamera(c);
        QVERIFY(waitRun(gen + 3));
        QVERIFY(!doc()->runs().runOutput()->depthReused);
        QVERIFY(doc()->runs().runOutput()->depth.depth != depth);
        w_->setLive(false);
    }

    // A Live edit shows its lists first, then the same generation again with
    // ground truth; the truth equals one computed directly on that run.
    void liveEditShowsListsThenGroundTruth() {
        openSmall();
        w_->setLive(true);
        QVERIFY(waitRun(doc()->runs().runGeneration() + 1));
        QSignalSpy finished(w_->cullService(), &CullService::finished);
        doc()->moveLight(2, doc()->scene().lights[2].position + glm::dvec3(0, 0.4, 0), doc()->newDragId());
        const quint64 g = w_->cullService()->lastGeneration();
        QTRY_VERIFY_WITH_TIMEOUT(doc()->runs().runGeneration() == g && doc()->runs().runOutput()->truthComputed, 60000);
        std::vector<std::shared_ptr<const lc::RunOutput>> ofG;
        for (const auto& args : finished)
            if (args.at(0).value<quint64>() == g)
                ofG.push_back(args.at(1).value<std::shared_ptr<const lc::RunOutput>>());
        QCOMPARE(int(ofG.size()), 2);
        QVERIFY(!ofG[0]->truthComputed);
        QVERIFY(ofG[1]->truthComputed);
        QVERIFY(ofG[0]->result.lightIndices == ofG[1]->result.lightIndices);
        const lc::GroundTruth direct = lc::computeGroundTruth(
            ofG[1]->depth, lc::Projection(doc()->scene().camera), ofG[1]->lights, ofG[1]->result, {false});
        QCOMPARE(ofG[1]->truth.metrics.falseNegatives, direct.metrics.falseNegatives);
        QCOMPARE(ofG[1]->truth.metrics.exactWork, direct.metrics.exactWork);
        QCOMPARE(ofG[1]->truth.metrics.shadingWork, direct.metrics.shadingWork);
        QVERIFY(direct.metrics.exactWork > 0);
        w_->setLive(false);
    }

    void addLightOnSurfaceUnderCursor() {
        openSmall();
        InspectorView* iv = w_->inspectorView();
        iv->renderNow();
        const QPoint centre(iv->width() / 2, iv->height() / 2);
        glm::dvec3 hit, normal;
        doc()->selection().setSelectedLights({});
        // Aim at the mesh, not at a light sphere: hide none, the picker ignores spheres here.
        QVERIFY(iv->pickSurface(centre, &hit, &normal));
        const int n = int(doc()->scene().lights.size());
        const int added = w_->addLightAt(centre);
        QCOMPARE(added, n);
        const auto [lo, hi] = doc()->scene().bounds();
        const double dist = glm::length(doc()->scene().lights[std::size_t(added)].position - hit);
        QVERIFY2(dist <= 0.011 * glm::length(hi - lo), qPrintable(QString::number(dist)));
        QCOMPARE(doc()->selection().selectedLights(), std::vector<int>{added});
        // Outside the view: the scene centre.
        const int atCentre = w_->addLightAtCentre();
        QCOMPARE(doc()->scene().lights[std::size_t(atCentre)].position, 0.5 * (lo + hi));
    }

    void cancelledImportLeavesSceneIntact() {
        openSmall();
        const std::string before = sceneText(doc());
        // While the import runs the window takes no input but Cancel (a
        // click on the toolbar's Add light is dropped: the scene compares
        // equal below); Cancel is pressed as soon as the status bar shows it,
        // and again at each poll while it shows (on a loaded machine the
        // first click can come before the status bar has laid the button
        // out, and land beside it).
        auto* fileBar = w_->findChild<QToolBar*>("fileToolbar");
        QWidget* addLight = fileBar ? fileBar->widgetForAction(w_->action("actionAddLight")) : nullptr;
        QVERIFY(addLight && addLight->isVisible());
        bool blockedClickSent = false, clicked = false;
        QTimer poll;
        connect(&poll, &QTimer::timeout, [&] {
            auto* cancel = w_->findChild<QToolButton*>("statusCancel_load");
            if (!cancel || !cancel->isVisible()) return;
            // Through the window, as the window system delivers real clicks.
            QWindow* window = w_->windowHandle();
            if (!blockedClickSent)
                QTest::mouseClick(window, Qt::LeftButton, Qt::NoModifier,
                                  addLight->mapTo(w_.get(), addLight->rect().center()));
            blockedClickSent = true;
            QTest::mouseClick(window, Qt::LeftButton, Qt::NoModifier, cancel->mapTo(w_.get(), cancel->rect().center()));
            clicked = true;
        });
        poll.start(10);
        // The import takes some 60 ms here: on a loaded machine it can end
        // before the first poll. Then it is undone (the click on Add light
        // must still have been dropped: the scene equals the one before) and
        // tried again, until Cancel comes in time.
        bool cancelled = false;
        for (int attempt = 0; attempt < 20 && !cancelled; ++attempt) {
            blockedClickSent = clicked = false;
            cancelled = !w_->importMeshFile(LC_ASSETS_DIR "/buildings/buildings.obj");
            if (!cancelled) {
                doc()->undoStack()->undo();
                QCOMPARE(sceneText(doc()), before);
            }
        }
        poll.stop();
        QVERIFY(cancelled);
        QVERIFY(clicked && blockedClickSent);
        QCOMPARE(sceneText(doc()), before);
        QVERIFY(w_->messageLog()->toPlainText().contains("cancelled"));
        QTRY_VERIFY(!w_->findChild<QToolButton*>("statusCancel_load"));
        // Input is back: the same click adds a light.
        const std::size_t lights = doc()->scene().lights.size();
        QTest::mouseClick(addLight, Qt::LeftButton);
        QCOMPARE(doc()->scene().lights.size(), lights + 1);
    }

    void dropImportsMesh() {
        openSmall();
        const std::size_t meshes = doc()->scene().meshes.size();
        QMimeData mime;
        mime.setUrls({QUrl::fromLocalFile(LC_ASSETS_DIR "/stanford_bunny/bun_zipper.ply")});
        // What a drag from a file manager delivers: enter (accepted), then drop.
        QDragEnterEvent enter(QPoint(200, 200), Qt::CopyAction, &mime, Qt::LeftButton, Qt::NoModifier);
        QApplication::sendEvent(w_.get(), &enter);
        QVERIFY(enter.isAccepted());
        QDropEvent drop(QPointF(200, 200), Qt::CopyAction, &mime, Qt::LeftButton, Qt::NoModifier);
        QApplication::sendEvent(w_.get(), &drop);
        QVERIFY2(doc()->scene().meshes.size() == meshes + 1, qPrintable(w_->messageLog()->toPlainText()));
        QCOMPARE(doc()->undoStack()->count(), 1);
    }

    void settingsPersist() {
        openSmall();
        QVERIFY(w_->setParamFromUi("algorithm", "halfz"));
        QVERIFY(w_->setParamFromUi("cells", "8"));
        w_->action("actionTabbedViews")->setChecked(true);
        const QString path = tmp_.path() + "/persist.json";
        QVERIFY(w_->saveAs(path));
        QVERIFY(w_->close());
        w_ = std::make_unique<MainWindow>();
        QVERIFY(doc()->runs().settings().algorithm == lc::Algorithm::HalfZ);
        QCOMPARE(doc()->runs().settings().cells, 8u);
        QVERIFY(w_->action("actionTabbedViews")->isChecked());
        bool listed = false;
        for (QAction* a : w_->findChildren<QAction*>())
            if (a->text() == QFileInfo(path).absoluteFilePath()) listed = true;
        QVERIFY(listed); // recent files
        w_->action("actionTabbedViews")->setChecked(false);
        QVERIFY(w_->setParamFromUi("algorithm", "2.5d"));
        QVERIFY(w_->setParamFromUi("cells", "32"));
        // Live comes back on, without a run of the window's empty scene
        // before any scene opens (the log began 'run 1: ..., 0 lights').
        w_->setLive(true);
        QVERIFY(w_->close());
        w_ = std::make_unique<MainWindow>();
        QVERIFY(w_->isLive());
        QTest::qWait(50);
        QCOMPARE(w_->cullService()->lastGeneration(), quint64(0));
        QVERIFY(!w_->messageLog()->toPlainText().contains("run 1"));
        w_->setLive(false);
        w_->close(); // leave default settings for the next tests
    }

    // The scriptable start: a screenshot of the whole window after the run.
    void scriptedScreenshot() {
        const QString shot = tmp_.path() + "/wall.png";
        QProcess studio;
        studio.start(LC_STUDIO_PATH, {"--builtin", "wall", "--run", "--screenshot", shot, "--quit"});
        QVERIFY(studio.waitForFinished(lctest::kRunTimeoutMs));
        QVERIFY2(studio.exitCode() == 0, studio.readAllStandardError().constData());
        QImage img(shot);
        QVERIFY(!img.isNull());
        QVERIFY(img.width() >= 800 && img.height() >= 500);
        // Not a blank grab: the window has many distinct colours (views, heat map, widgets).
        QSet<QRgb> colours;
        for (int y = 0; y < img.height(); y += 7)
            for (int x = 0; x < img.width(); x += 7) colours.insert(img.pixel(x, y));
        QVERIFY(colours.size() > 50);

        QVERIFY(!QString::fromUtf8(studio.readAllStandardOutput()).contains("shaded pictures"));

        // In a shaded image mode the screenshot waits for the pictures; the
        // mode is remembered as a pick in View > Camera image is; a mode
        // that does not exist is a clear error.
        const QString shaded = tmp_.path() + "/wall-difference.png";
        QProcess pictures;
        pictures.start(LC_STUDIO_PATH,
                       {"--builtin", "wall", "--image-mode", "difference", "--screenshot", shaded, "--quit"});
        QVERIFY(pictures.waitForFinished(lctest::kRunTimeoutMs));
        QVERIFY2(pictures.exitCode() == 0, pictures.readAllStandardError().constData());
        const QString said = QString::fromUtf8(pictures.readAllStandardOutput());
        QVERIFY2(said.contains("screenshot written to " + shaded + " (with the shaded pictures)"), qPrintable(said));
        QVERIFY(!QImage(shaded).isNull());
        QSettings studioSettings("LightCull", "LightCull Studio"); // the studio's own, in this run's folder
        studioSettings.sync();
        QCOMPARE(studioSettings.value("cameraView/imageMode").toString(), QString("difference"));
        QProcess badMode;
        badMode.start(LC_STUDIO_PATH, {"--image-mode", "shaded", "--quit"});
        QVERIFY(badMode.waitForFinished(30000));
        QCOMPARE(badMode.exitCode(), 2);
        QVERIFY(QString::fromUtf8(badMode.readAllStandardError()).contains("--image-mode: expected heat"));
        studioSettings.setValue("cameraView/imageMode", "heat"); // the next start is the default one
        studioSettings.sync();

        // Without a display: a clear message, a non-zero exit, no crash.
        QProcess headless;
        QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
        env.remove("DISPLAY");
        env.remove("QT_QPA_PLATFORM");
        headless.setProcessEnvironment(env);
        headless.start(LC_STUDIO_PATH, {"--builtin", "wall"});
        QVERIFY(headless.waitForFinished(30000));
        QCOMPARE(headless.exitStatus(), QProcess::NormalExit);
        QCOMPARE(headless.exitCode(), 2);
        QVERIFY(QString::fromUtf8(headless.readAllStandardError()).contains("xvfb-run"));
    }

    // The shading benchmark as a user starts it: it measures both kinds of
    // rounds, the algorithm switch keeping the all-lights image and the moved
    // light shading a new one, and says so; bad rounds are a clear error.
    void scriptedShadingBenchmark() {
        QProcess studio;
        studio.start(LC_STUDIO_PATH, {"--builtin", "wall", "--measure-shading", "2"});
        QVERIFY(studio.waitForFinished(lctest::kRunTimeoutMs));
        const QString out = QString::fromUtf8(studio.readAllStandardOutput());
        QVERIFY2(studio.exitCode() == 0, studio.readAllStandardError().constData());
        QVERIFY2(out.contains("1 rounds, all-lights image updated each: yes"), qPrintable(out));
        QVERIFY2(out.contains("1 rounds, all-lights image kept each: yes"), qPrintable(out));

        QProcess bad;
        bad.start(LC_STUDIO_PATH, {"--builtin", "wall", "--measure-shading", "1"});
        QVERIFY(bad.waitForFinished(30000));
        QCOMPARE(bad.exitCode(), 2);
        QVERIFY(QString::fromUtf8(bad.readAllStandardError()).contains("--measure-shading: expected rounds in [2, 1000]"));
    }

    void tenThousandLightsStayOneActor() {
        openSmall();
        // Radii up to sqrt(10 / 1) = 3.2: a dense but readable cloud.
        lc::LightGenSettings g = lc::defaultLightGen(doc()->scene(), 10000, 3);
        g.minIntensity = 1.0;
        QVERIFY(w_->generateLights(g));
        auto* glyphInput = vtkPolyData::SafeDownCast(
            w_->inspectorView()->lightActor()->GetMapper()->GetInputAlgorithm()->GetInputDataObject(0, 0));
        QCOMPARE(glyphInput->GetNumberOfPoints(), vtkIdType(doc()->scene().lights.size()));
        // Not an assertion (benchmarks are not tests): the figures go to the log.
        InspectorView* view = w_->inspectorView();
        view->renderNow(); // builds the glyphs
        QElapsedTimer t;
        t.start();
        for (int i = 0; i < 3; ++i) view->renderNow();
        qInfo("inspector view %dx%d, %zu light spheres in one glyph actor: %.0f ms per frame (Xvfb, llvmpipe)",
              view->width(), view->height(), doc()->scene().lights.size(), t.elapsed() / 3.0);
        QVERIFY(doc()->selection().selectedLights().empty()); // a generated cloud is not selected wholesale
        // Picking a light through the glyph maps back to the light index: aim
        // at a light's centre; the hit lies on the picked light's sphere (the
        // 12x8 facets sit up to 8% inside it).
        InspectorView* iv = w_->inspectorView();
        vtkRenderer* ren = iv->renderer();
        const auto& lights = doc()->scene().lights;
        int tried = 0;
        for (std::size_t i = lights.size(); i-- > 0 && tried < 3;) {
            ren->SetWorldPoint(lights[i].position.x, lights[i].position.y, lights[i].position.z, 1.0);
            ren->WorldToDisplay();
            double d[3];
            ren->GetDisplayPoint(d);
            const QPoint pos(int(d[0] / iv->devicePixelRatioF()), int(iv->height() - 1 - d[1] / iv->devicePixelRatioF()));
            if (!iv->rect().adjusted(5, 5, -5, -5).contains(pos)) continue;
            ++tried;
            glm::dvec3 hit;
            const int picked = iv->pickLight(pos, &hit);
            QVERIFY(picked >= 0 && picked < int(lights.size()));
            const double r = lights[std::size_t(picked)].radius();
            const double dist = glm::length(hit - lights[std::size_t(picked)].position);
            QVERIFY2(dist <= r * 1.001 && dist >= r * 0.9, qPrintable(QString("picked %1: |hit-c| %2, r %3").arg(picked).arg(dist).arg(r)));
        }
        QVERIFY(tried > 0);
    }
};

LC_STUDIO_TEST_MAIN(StudioTest)
#include "test_studio.moc"
