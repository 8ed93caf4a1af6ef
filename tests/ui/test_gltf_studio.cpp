// glTF in the studio, as a user gets there: File > Open and drag-and-drop of a
// .glb (its lights culled through its own camera), a broken file that leaves
// the scene being edited intact, Save As .glb, the light cut-off setting, and
// an independent check of our reader and writer against VTK's own glTF
// importer (triangles, bounds and light positions of the same file).

#include "studio_test_support.hpp"

#include "document/document.hpp"
#include "window/main_window.hpp"

#include "culling/core/file_io.hpp"
#include "culling/scene/gltf_io.hpp"
#include "culling/core/pipeline.hpp"
#include "culling/scene/scene_io.hpp"

#include <QAction>
#include <QElapsedTimer>
#include <QLabel>
#include <QMessageBox>
#include <QMimeData>
#include <QPlainTextEdit>
#include <QRegularExpression>
#include <QUndoStack>
#include <QUrl>

#include <vtkActor.h>
#include <vtkActorCollection.h>
#include <vtkGLTFImporter.h>
#include <vtkLight.h>
#include <vtkLightCollection.h>
#include <vtkMapper.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>

#include <nlohmann/json.hpp>

#include <fstream>

using namespace lcui;

namespace {


// The atrium with 48 lights (a third of them spots) at 320x180, as a glTF.
lc::Scene smallAtrium() {
    lc::Scene s = lc::makeBuiltinScene("atrium");
    lc::LightGenSettings g = lc::defaultLightGen(s, 48, 5);
    g.spotFraction = 0.33;
    s.lights = lc::generateLights(g);
    s.camera.width = 320;
    s.camera.height = 180;
    return s;
}

} // namespace

class GltfStudioTest : public QObject {
    Q_OBJECT
    std::unique_ptr<MainWindow> w_;
    QTemporaryDir tmp_;
    Document* doc() const { return w_->document(); }

    bool waitRun() {
        QSignalSpy done(w_.get(), &MainWindow::runFinished);
        QSignalSpy failed(w_.get(), &MainWindow::runFailed);
        QElapsedTimer t;
        t.start();
        while (!doc()->runs().runOutput() && failed.isEmpty() && t.elapsed() < lctest::kRunTimeoutMs) done.wait(200);
        return doc()->runs().runOutput() != nullptr;
    }
    QString writeAtrium(const QString& name) {
        const QString p = tmp_.path() + "/" + name;
        lc::saveGltfScene(smallAtrium(), p.toStdString());
        return p;
    }

private slots:
    void init() {
        w_ = lctest::makeTestWindow();
        QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
    }
    void cleanup() {
        doc()->undoStack()->setClean();
        w_.reset();
    }

    void openGlbThroughFileMenuCullsItsLightsThroughItsCamera() {
        const QString p = writeAtrium("atrium.glb");
        w_->prompts.openPath = [&](QWidget*, const QString&, const QString& filter) {
            // The dialog offers glTF beside scene JSON.
            if (!filter.contains("*.glb") || !filter.contains("*.gltf")) return QString();
            return p;
        };
        w_->runOnOpen = true;
        w_->action("actionOpen")->trigger();
        QCOMPARE(doc()->scene().lights.size(), std::size_t(48));
        QCOMPARE(doc()->scene().camera.width, 320u); // the file's camera, its resolution kept
        QVERIFY(doc()->scene().camera == lc::loadGltfScene(p.toStdString()).camera);
        QVERIFY(waitRun());
        const auto out = doc()->runs().runOutput();
        QCOMPARE(out->truth.metrics.falseNegatives, std::uint64_t(0));
        QVERIFY(out->truth.metrics.shadingWork > 0);
        QVERIFY(w_->messageLog()->toPlainText().contains("48 lights, camera: cameras[0] 'culling camera'"));
        QVERIFY(w_->messageLog()->toPlainText().contains(QRegularExpression("loaded in [0-9]+ ms")));
    }

    void dropOfAGlbOpensItAsAScene() {
        QVERIFY(w_->openBuiltin("forest"));
        const QString p = writeAtrium("dropped.glb");
        QMimeData mime;
        mime.setUrls({QUrl::fromLocalFile(p)});
        QDragEnterEvent enter(QPoint(200, 200), Qt::CopyAction, &mime, Qt::LeftButton, Qt::NoModifier);
        QApplication::sendEvent(w_.get(), &enter);
        QVERIFY(enter.isAccepted());
        QDropEvent drop(QPointF(200, 200), Qt::CopyAction, &mime, Qt::LeftButton, Qt::NoModifier);
        QApplication::sendEvent(w_.get(), &drop);
        QCOMPARE(doc()->scene().lights.size(), std::size_t(48));
        QCOMPARE(doc()->filePath(), p);
    }

    void brokenGltfLeavesTheEditedSceneIntact() {
        QVERIFY(w_->openBuiltin("atrium"));
        doc()->deleteLights({0}); // an unsaved edit
        const std::string before = lc::serializeScene(doc()->scene());
        const QString good = writeAtrium("good.glb");
        std::string bytes;
        {
            std::ifstream in(good.toStdString(), std::ios::binary);
            bytes.assign(std::istreambuf_iterator<char>(in), {});
        }
        const QString bad = tmp_.path() + "/truncated.glb";
        std::ofstream(bad.toStdString(), std::ios::binary).write(bytes.data(), std::streamsize(bytes.size() / 2));
        QString shown;
        w_->prompts.showError = [&](QWidget*, const QString&, const QString& m) { shown = m; };
        w_->prompts.askUnsaved = [](QWidget*, const QString&) { return QMessageBox::Discard; };
        QVERIFY(!w_->openSceneFile(bad));
        QVERIFY2(shown.contains("truncated.glb: header.length"), qPrintable(shown));
        QCOMPARE(lc::serializeScene(doc()->scene()), before);
    }

    void saveAsGlbWritesWhatReadsBack() {
        QVERIFY(w_->openBuiltin("atrium"));
        const QString p = tmp_.path() + "/saved.glb";
        w_->prompts.savePath = [&](QWidget*, const QString&, const QString& filter) {
            return filter.contains("*.glb") ? p : QString();
        };
        w_->action("actionSaveAs")->trigger();
        const lc::Scene back = lc::loadGltfScene(p.toStdString());
        QCOMPARE(back.triangleCount(), doc()->scene().triangleCount());
        QCOMPARE(back.lights.size(), doc()->scene().lights.size());
        for (std::size_t i = 0; i < back.lights.size(); ++i)
            QVERIFY(std::abs(back.lights[i].radius() - doc()->scene().lights[i].radius()) < 1e-9);
        QCOMPARE(doc()->filePath(), p);
        QVERIFY(doc()->undoStack()->isClean());
    }

    // A .glb another tool wrote holds what this tool's writer drops
    // (materials, textures, animations): Save never overwrites it, it asks for
    // a new file and says why; Save As onto it is refused. An export of the
    // edited scene records the file and the edit, and writes the edited scene.
    void saveNeverOverwritesAForeignGltfAndExportRecordsTheEdit() {
        const QString src = tmp_.path() + "/sponza.gltf";
        {
            auto j = nlohmann::json::parse(lc::serializeGltf(smallAtrium(), false));
            j["asset"]["generator"] = "Khronos glTF Blender I/O";
            std::ofstream(src.toStdString()) << j.dump();
        }
        const auto bytes = [](const QString& path) {
            std::ifstream in(path.toStdString(), std::ios::binary);
            return std::string(std::istreambuf_iterator<char>(in), {});
        };
        const std::string original = bytes(src);
        w_->runOnOpen = true;
        QVERIFY(w_->openSceneFile(src));
        QVERIFY(waitRun());
        doc()->deleteLights({0}); // an unsaved edit
        QVERIFY(doc()->isDirty());

        // Export: the record says which file, which version, edited, and the
        // edited scene is there to reproduce the figures.
        QVERIFY(lctest::waitRun(*w_, w_->runCulling(), true));
        const QString dir = tmp_.path() + "/export";
        QVERIFY(lctest::exportAndWait(*w_, dir));
        const auto summary = nlohmann::json::parse(bytes(dir + "/summary.json"));
        const auto& source = summary["scene_source"];
        QCOMPARE(QString::fromStdString(source["file"].get<std::string>()), QFileInfo(src).absoluteFilePath());
        QCOMPARE(source["content_hash_fnv1a64"].get<std::string>(), lc::fileHashFnv1a64(src.toStdString()));
        QVERIFY(source["edited"].get<bool>());
        QCOMPARE(source["gltf_min_intensity"].get<double>(), w_->gltfOptions.minIntensity);
        QVERIFY(source["gltf_camera"].get<std::string>().find("culling camera") != std::string::npos);
        const lc::Scene edited = lc::loadSceneFile((dir + "/scene.json").toStdString());
        QCOMPARE(edited.lights.size(), std::size_t(47));
        QCOMPARE(edited.triangleCount(), doc()->scene().triangleCount());

        QString caption;
        const QString fresh = tmp_.path() + "/sponza-lit.glb";
        w_->prompts.savePath = [&](QWidget*, const QString& c, const QString&) {
            caption = c;
            return fresh;
        };
        w_->action("actionSave")->trigger();
        QVERIFY2(caption.contains("sponza.gltf stays as it is"), qPrintable(caption));
        QVERIFY(w_->messageLog()->toPlainText().contains("would lose its materials, textures, animations"));
        QCOMPARE(bytes(src), original);
        QCOMPARE(doc()->filePath(), fresh);
        QCOMPARE(lc::loadGltfScene(fresh.toStdString()).lights.size(), std::size_t(47));
        // Now the document is our own file: Save writes it without asking.
        caption.clear();
        doc()->deleteLights({0});
        w_->action("actionSave")->trigger();
        QVERIFY(caption.isEmpty());
        QCOMPARE(lc::loadGltfScene(fresh.toStdString()).lights.size(), std::size_t(46));

        // Save As onto the foreign file, from a scene opened from it: refused.
        QVERIFY(w_->openSceneFile(src));
        QString shown;
        w_->prompts.showError = [&](QWidget*, const QString&, const QString& m) { shown = m; };
        doc()->deleteLights({0});
        QVERIFY(!w_->saveAs(src));
        QVERIFY2(shown.contains("sponza.gltf was written by another tool"), qPrintable(shown));
        QCOMPARE(bytes(src), original);
        QVERIFY(doc()->isDirty());
    }

    void lightCutoffSettingSetsTheRadiusOfLightsWithoutRange() {
        // A glTF light without `range`: its radius comes from I_min.
        lc::Scene s = smallAtrium();
        s.lights.resize(1);
        s.lights[0].kind = lc::LightKind::Point;
        s.lights[0].intensity = 8.0;
        s.lights[0].color = glm::dvec3(1.0);
        s.lights[0].explicitRadius = 0.0;
        const QString p = tmp_.path() + "/norange.gltf";
        {
            // Drop our extras and the range so the reader falls back to I_min.
            std::string text = lc::serializeGltf(s, false);
            auto j = nlohmann::json::parse(text);
            auto& light = j["extensions"]["KHR_lights_punctual"]["lights"][0];
            light.erase("range");
            light.erase("extras");
            std::ofstream(p.toStdString()) << j.dump();
        }
        w_->prompts.askNumber = [](QWidget*, const QString&, const QString&, double, double, double& v) {
            v = 0.5;
            return true;
        };
        w_->action("actionGltfCutoff")->trigger();
        QCOMPARE(w_->gltfOptions.minIntensity, 0.5);
        QVERIFY(w_->openSceneFile(p));
        QCOMPARE(doc()->scene().lights.size(), std::size_t(1));
        QVERIFY(std::abs(doc()->scene().lights[0].radius() - std::sqrt(8.0 / 0.5)) < 1e-12);
        // The setting persists into a new window.
        w_.reset();
        w_ = lctest::makeTestWindow();
        QCOMPARE(w_->gltfOptions.minIntensity, 0.5);
        w_->setGltfMinIntensity(lc::kGltfDefaultMinIntensity);
    }

    // File > glTF light cut-off acts on the open scene: the lights without a
    // range get the new radius at once, as one undo step; lights with a range
    // keep theirs; the status bar names the cut-off; radii wider than the
    // scene are warned about.
    void lightCutoffAppliesToTheOpenSceneAsOneUndoStep() {
        lc::Scene s = smallAtrium();
        s.lights.resize(2);
        for (auto& l : s.lights) {
            l.kind = lc::LightKind::Point;
            l.intensity = 80.0;
            l.color = glm::dvec3(1.0);
        }
        s.lights[0].explicitRadius = 0.0;
        s.lights[1].explicitRadius = 1.5;
        const QString p = tmp_.path() + "/cutoff.gltf";
        {
            auto j = nlohmann::json::parse(lc::serializeGltf(s, false));
            auto& light = j["extensions"]["KHR_lights_punctual"]["lights"][0];
            light.erase("range");
            light.erase("extras");
            std::ofstream(p.toStdString()) << j.dump();
        }
        w_->runOnOpen = false;
        w_->setGltfMinIntensity(lc::kGltfDefaultMinIntensity);
        QVERIFY(w_->openSceneFile(p));
        const double before = doc()->scene().lights[0].radius();
        QVERIFY(std::abs(before - std::sqrt(80.0 / lc::kGltfDefaultMinIntensity)) < 1e-9);
        // sqrt(80 / 0.01) = 89 m, wider than the atrium: warned.
        const auto* cutLabel = w_->findChild<QLabel*>("statusCutoff");
        QVERIFY(cutLabel);
        QVERIFY2(cutLabel->text().contains("cut-off 0.01 lux (1 light)"), qPrintable(cutLabel->text()));
        QVERIFY(!lc::cutoffCoverageWarning(doc()->scene()).empty());
        const int steps = doc()->undoStack()->count();

        w_->prompts.askNumber = [](QWidget*, const QString&, const QString&, double, double, double& v) {
            v = 2.0;
            return true;
        };
        w_->action("actionGltfCutoff")->trigger();
        QCOMPARE(doc()->undoStack()->count(), steps + 1);
        QVERIFY(std::abs(doc()->scene().lights[0].radius() - std::sqrt(40.0)) < 1e-12); // sqrt(80 / 2)
        QCOMPARE(doc()->scene().lights[1].radius(), 1.5);
        QVERIFY2(cutLabel->text().contains("cut-off 2 lux"), qPrintable(cutLabel->text()));
        QVERIFY(w_->messageLog()->toPlainText().contains("radii of 1 light without a range re-derived"));
        QVERIFY(lc::cutoffCoverageWarning(doc()->scene()).empty());

        doc()->undoStack()->undo();
        QVERIFY(std::abs(doc()->scene().lights[0].radius() - before) < 1e-12);
        QVERIFY2(cutLabel->text().contains("cut-off 0.01 lux"), qPrintable(cutLabel->text()));
        w_->setGltfMinIntensity(lc::kGltfDefaultMinIntensity);
    }

    // VTK's importer is a second, independent reader of the same files.
    void vtkImporterAgreesWithOurReaderAndWriter() {
        const lc::Scene scene = smallAtrium();
        for (const char* name : {"vtk.glb", "vtk.gltf"}) {
            const QString p = tmp_.path() + "/" + name;
            lc::saveGltfScene(scene, p.toStdString());
            const lc::Scene ours = lc::loadGltfScene(p.toStdString());

            vtkNew<vtkRenderer> ren;
            vtkNew<vtkRenderWindow> rw;
            rw->SetOffScreenRendering(1);
            rw->AddRenderer(ren);
            vtkNew<vtkGLTFImporter> imp;
            imp->SetFileName(p.toUtf8().constData());
            imp->SetRenderWindow(rw);
            imp->Update();

            vtkIdType tris = 0;
            double b[6] = {1e300, -1e300, 1e300, -1e300, 1e300, -1e300};
            vtkActorCollection* actors = ren->GetActors();
            actors->InitTraversal();
            while (vtkActor* a = actors->GetNextActor()) {
                auto* pd = vtkPolyData::SafeDownCast(a->GetMapper()->GetInput());
                QVERIFY(pd);
                tris += pd->GetNumberOfPolys();
                double ab[6];
                a->GetBounds(ab);
                for (int k = 0; k < 3; ++k) {
                    b[2 * k] = std::min(b[2 * k], ab[2 * k]);
                    b[2 * k + 1] = std::max(b[2 * k + 1], ab[2 * k + 1]);
                }
            }
            QCOMPARE(std::size_t(tris), ours.triangleCount());
            QCOMPARE(std::size_t(tris), scene.triangleCount());
            const auto [lo, hi] = ours.bounds();
            for (int k = 0; k < 3; ++k) {
                QVERIFY2(std::abs(b[2 * k] - lo[k]) < 1e-4, qPrintable(QString("min %1: vtk %2 ours %3").arg(k).arg(b[2 * k]).arg(lo[k])));
                QVERIFY2(std::abs(b[2 * k + 1] - hi[k]) < 1e-4, qPrintable(QString("max %1").arg(k)));
            }
            // Lights: VTK adds each KHR_lights_punctual light with its node's
            // world matrix as the light's transform (the light sits at that
            // frame's origin; VTK's own position is left at its default).
            std::vector<glm::dvec3> vtkPositions;
            vtkLightCollection* lights = ren->GetLights();
            lights->InitTraversal();
            while (vtkLight* l = lights->GetNextItem()) {
                if (!l->GetPositional()) continue;
                vtkMatrix4x4* m = l->GetTransformMatrix();
                QVERIFY(m);
                vtkPositions.emplace_back(m->GetElement(0, 3), m->GetElement(1, 3), m->GetElement(2, 3));
            }
            QCOMPARE(vtkPositions.size(), ours.lights.size());
            for (const auto& l : ours.lights) {
                double best = 1e300;
                for (const auto& v : vtkPositions) best = std::min(best, glm::length(v - l.position));
                // VTK keeps the node matrices in single precision: 1e-4 at
                // coordinates of tens of metres is a few float ulps.
                QVERIFY2(best < 1e-4, qPrintable(QString("%1 at %2 %3 %4; vtk's first at %5 %6 %7")
                                                     .arg(QString::fromStdString(l.name))
                                                     .arg(l.position.x).arg(l.position.y).arg(l.position.z)
                                                     .arg(vtkPositions[0].x).arg(vtkPositions[0].y).arg(vtkPositions[0].z)));
            }
        }
    }
};

LC_STUDIO_TEST_MAIN(GltfStudioTest)
#include "test_gltf_studio.moc"
