// The camera view's image modes (issue 7): Shaded (culled lists), Shaded (all
// lights) and Difference, computed on the culling worker with the selected
// backend. Qt Test under Xvfb driving the real MainWindow: the picture the
// view shows (its vtkImageData, not a screenshot) must equal, pixel for pixel,
// the PNG that `lightcull run --shaded-images` writes for the same scene and
// backend, and the legend's image error must be summary.json's. Also: shading
// only when a mode needs it, the lists before the images in Live mode, a newer
// request cancelling shading, the mode persisting, and File > Export
// diagnostics writing the three PNGs.

#include "studio_test_support.hpp"

#include "views/camera_view.hpp"
#include "work/cull_worker.hpp"
#include "document/document.hpp"
#include "window/main_window.hpp"

#include "culling/core/backend.hpp"
#include "culling/diagnostics/export.hpp"
#include "culling/scene/scene_io.hpp"

#include <QAction>
#include <QDir>
#include <QElapsedTimer>
#include <QFile>
#include <QFileInfo>
#include <QImage>
#include <QLabel>
#include <QPlainTextEdit>
#include <QProcess>
#include <QProgressBar>
#include <QSignalSpy>
#include <QTimer>
#include <QToolButton>
#include <QUndoStack>

#include <nlohmann/json.hpp>
#include <vtkImageData.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>

#include <map>
#include <memory>

using namespace lcui;
using Mode = CameraView::ImageMode;

namespace {

const char* const kModes[] = {"shaded-culled", "shaded-all", "difference"};
const char* const kPngOfMode[] = {"shaded_culled.png", "shaded_all.png", "shaded_diff.png"};

// Pixels of a vtkImageData (RGB8, VTK rows upwards) that differ from a PNG
// (rows downwards); -1 when the sizes or formats disagree.
long differingPixels(vtkImageData* shown, const QString& pngPath) {
    QImage png(pngPath);
    if (png.isNull() || !shown) return -1;
    png = png.convertToFormat(QImage::Format_RGB888);
    int dims[3];
    shown->GetDimensions(dims);
    if (dims[0] != png.width() || dims[1] != png.height() || dims[2] != 1 ||
        shown->GetNumberOfScalarComponents() != 3 || shown->GetScalarType() != VTK_UNSIGNED_CHAR)
        return -1;
    const auto* data = static_cast<const std::uint8_t*>(shown->GetScalarPointer());
    long differing = 0;
    for (int y = 0; y < png.height(); ++y) {
        const std::uint8_t* row = png.constScanLine(y);
        const std::uint8_t* vrow = data + std::size_t(png.height() - 1 - y) * std::size_t(png.width()) * 3;
        for (int x = 0; x < png.width() * 3; x += 3)
            if (row[x] != vrow[x] || row[x + 1] != vrow[x + 1] || row[x + 2] != vrow[x + 2]) ++differing;
    }
    return differing;
}

nlohmann::json readJson(const QString& path) {
    QFile f(path);
    if (!f.open(QIODevice::ReadOnly)) return {};
    return nlohmann::json::parse(f.readAll().toStdString(), nullptr, false);
}

bool vulkanAvailable() {
    for (const auto& b : lc::availableBackends())
        if (b == "vulkan") return true;
    return false;
}

} // namespace

class ShadedViewTest : public QObject {
    Q_OBJECT

    std::unique_ptr<MainWindow> w_;
    QTemporaryDir tmp_;
    std::map<QString, QString> cliDirs_; // backend-algorithm -> the CLI's --out folder

    Document* doc() { return w_->document(); }
    CameraView* cv() { return w_->cameraView(); }

    // Runs `lightcull run --shaded-images` once per backend on the scene the
    // studio tests open.
    QString cliOut(const QString& backend, const QString& algorithm = "2.5d") {
        const QString key = backend + "-" + algorithm;
        if (cliDirs_.count(key)) return cliDirs_[key];
        const QString out = tmp_.path() + "/cli-" + key;
        QProcess cli;
        cli.start(LC_CLI_PATH, {"run", "--builtin", "atrium", "--width", "320", "--height", "180", "--tile", "16",
                                "--algorithm", algorithm, "--backend", backend, "--shaded-images", "--out", out});
        if (!cli.waitForFinished(lctest::kRunTimeoutMs) || cli.exitCode() != 0) {
            qWarning("lightcull failed: %s", cli.readAllStandardError().constData());
            return {};
        }
        return cliDirs_[key] = out;
    }

    // Waits until the shown run is `generation` with its shaded images.
    bool waitShaded(quint64 generation) {
        QElapsedTimer t;
        t.start();
        while (t.elapsed() < lctest::kRunTimeoutMs) {
            const auto run = doc()->runs().runOutput();
            if (doc()->runs().runGeneration() == generation && run && !run->shadedAll.empty()) return true;
            if (doc()->runs().runGeneration() > generation) return false;
            QTest::qWait(20);
        }
        return false;
    }
    bool waitRun(quint64 generation) { return lctest::waitRun(*w_, generation, true); }

    void openSmall(const QString& backend = "cpu") {
        QVERIFY(lctest::openBuiltinWith(*w_, "atrium",
                                        {{"width", "320"}, {"height", "180"}, {"tile", "16"}, {"algorithm", "2.5d"}}));
        w_->setBackend(backend);
    }

    void pickMode(const char* name) {
        QAction* a = w_->action(QString("actionImage_%1").arg(name));
        QVERIFY2(a, name);
        a->trigger(); // what the View > Camera image menu does
        QCOMPARE(QString(CameraView::toString(cv()->imageMode())), QString(name));
    }

    void saveShot(const QString& name) {
        cv()->renderNow();
        QTest::qWait(30);
        cv()->renderNow();
        QDir().mkpath(LC_RENDER_OUT_DIR);
        QVERIFY(cv()->grabFramebuffer().save(QString(LC_RENDER_OUT_DIR) + "/" + name + ".png"));
    }

private slots:
    void init() {
        w_ = lctest::makeTestWindow();
        QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
    }

    void cleanup() {
        if (w_) {
            doc()->undoStack()->setClean();
            w_->action("actionImage_heat")->trigger(); // the next test starts from the default
        }
        w_.reset();
    }

    // Each mode shows exactly the CLI's PNG of the same scene and backend;
    // the Difference legend states summary.json's RMSE and max error; the
    // tile grid and a click on a tile keep working over the pictures.
    void modesMatchCliPngs_data() {
        QTest::addColumn<QString>("backend");
        QTest::newRow("cpu") << "cpu";
        // The studio's default backend where a device exists (lavapipe in CI).
        QVERIFY2(vulkanAvailable(), "no Vulkan backend: the studio would fall back to the CPU");
        QTest::newRow("vulkan") << "vulkan";
    }
    void modesMatchCliPngs() {
        QFETCH(QString, backend);
        const QString cli = cliOut(backend);
        QVERIFY(!cli.isEmpty());
        openSmall(backend);
        QSignalSpy shadingStarted(w_->cullService(), &CullService::shadingStarted);
        pickMode("shaded-culled");
        const quint64 gen = w_->runCulling();
        QVERIFY(waitShaded(gen));
        QCOMPARE(QString::fromStdString(doc()->runs().runOutput()->result.backend), backend);
        QCOMPARE(shadingStarted.count(), 1); // shaded once, for this run
        QTRY_VERIFY(cv()->shownImage() != nullptr);
        QVERIFY(cv()->shownImageRun() == doc()->runs().runOutput().get());

        const nlohmann::json summary = readJson(cli + "/summary.json");
        QVERIFY(summary.is_object());
        const double rmse = summary["metrics"]["image_rmse"].get<double>();
        const double maxError = summary["metrics"]["image_max_error"].get<double>();
        QVERIFY(maxError > 0); // atrium's cut-off leaves an error: the difference picture is not black
        for (int i = 0; i < 3; ++i) {
            pickMode(kModes[i]);
            cv()->renderNow();
            QCOMPARE(differingPixels(cv()->shownImage(), cli + "/" + kPngOfMode[i]), 0L);
            saveShot(QString("shaded_view_%1_%2").arg(kModes[i], backend));
        }
        // Difference mode: the legend is the grey ramp from 0 to the max error,
        // and the numbers are summary.json's.
        QCOMPARE(cv()->shownImageRmse(), rmse);
        QCOMPARE(cv()->shownImageMaxError(), maxError);
        QVERIFY(cv()->legend() && !cv()->legend()->GetVisibility());
        QVERIFY2(cv()->imageLabelText().contains(QString::number(rmse, 'g', 6)), qPrintable(cv()->imageLabelText()));
        QVERIFY2(cv()->imageLabelText().contains(QString::number(maxError, 'g', 6)), qPrintable(cv()->imageLabelText()));

        // A click on a tile over the picture selects that tile.
        const double* vp = cv()->sceneRenderer()->GetViewport();
        const int tx = 7, ty = 4;
        const double u = (tx * 16 + 8) / 320.0, v = (ty * 16 + 8) / 180.0;
        const QPoint click(int((vp[0] + u * (vp[2] - vp[0])) * cv()->width()),
                           int((1.0 - (vp[3] - v * (vp[3] - vp[1]))) * cv()->height()));
        QTest::mouseClick(cv(), Qt::LeftButton, {}, click);
        QTRY_COMPARE(doc()->selection().selectedTile(), ty * 20 + tx);
    }

    // Comparing algorithms in Difference mode: the next run keeps the
    // all-lights image (it depends on the pixels and lights, not the lists)
    // and shades only its culled one, and its three pictures and error are
    // still exactly the CLI's for that algorithm; a moved light's image is
    // the kept one updated by its old and new terms (test_shade.cpp holds
    // the updates to a fresh image).
    void algorithmChangeKeepsTheAllLightsImage() {
        QVERIFY2(vulkanAvailable(), "no Vulkan backend: the studio would fall back to the CPU");
        const QString cli = cliOut("vulkan", "clustered");
        QVERIFY(!cli.isEmpty());
        openSmall("vulkan");
        pickMode("difference");
        QVERIFY(waitShaded(w_->runCulling()));
        QVERIFY(!doc()->runs().runOutput()->allLightsReused);
        const std::vector<float> all = doc()->runs().runOutput()->shadedAll;

        QVERIFY(w_->setParamFromUi("algorithm", "clustered"));
        QVERIFY(waitShaded(w_->runCulling()));
        QVERIFY(doc()->runs().runOutput()->allLightsReused);
        QVERIFY(doc()->runs().runOutput()->shadedAll == all);
        for (int i = 0; i < 3; ++i) {
            pickMode(kModes[i]);
            cv()->renderNow();
            QCOMPARE(differingPixels(cv()->shownImage(), cli + "/" + kPngOfMode[i]), 0L);
        }
        const nlohmann::json summary = readJson(cli + "/summary.json");
        QCOMPARE(cv()->shownImageRmse(), summary["metrics"]["image_rmse"].get<double>());

        const glm::dvec3 p = doc()->scene().lights[0].position;
        doc()->moveLight(0, p + glm::dvec3(0.3, 0, 0), doc()->newDragId());
        QVERIFY(waitShaded(w_->runCulling()));
        const auto moved = doc()->runs().runOutput();
        QVERIFY(!moved->allLightsReused);
        QVERIFY(moved->shadedAll != all);
        QVERIFY(moved->allLightsUpdate.has_value());
        QCOMPARE(moved->allLightsUpdate->removed, std::size_t(1));
        QCOMPARE(moved->allLightsUpdate->added, std::size_t(1));
        const auto* logView = w_->findChild<QPlainTextEdit*>("messageLog");
        QTRY_VERIFY2(logView->toPlainText().contains(
                         "all-lights image updated for the lights that changed: terms out 1, in 1;"),
                     qPrintable(logView->toPlainText().right(1500)));
        cv()->renderNow();
        QVERIFY(w_->grab().save(QString(LC_RENDER_OUT_DIR) + "/shaded_view_moved_light_window.png"));
    }

    // In the heat-map mode nothing is shaded; picking a shaded mode shades
    // the shown run on the worker ("shading..." in the status bar meanwhile),
    // as the same generation.
    void shadingOnlyWhenAModeNeedsIt() {
        openSmall();
        QSignalSpy started(w_->cullService(), &CullService::shadingStarted);
        QSignalSpy ended(w_->cullService(), &CullService::shadingEnded);
        const quint64 gen = w_->runCulling();
        QVERIFY(waitRun(gen));
        QTest::qWait(100); // any shading would have started by now
        QCOMPARE(started.count(), 0);
        QVERIFY(doc()->runs().runOutput()->shadedAll.empty());
        QVERIFY(cv()->shownImage() == nullptr);
        QVERIFY(cv()->imageLabelText().isEmpty());

        QString seen;
        QObject ctx;
        connect(w_->cullService(), &CullService::shadingStarted, &ctx, [&] {
            QTimer::singleShot(0, &ctx, [&] { // after the window's own slot made the row
                if (auto* label = w_->findChild<QLabel*>("statusTask_shading")) seen = label->text();
            });
        });
        pickMode("difference");
        QVERIFY(waitShaded(gen));
        QCOMPARE(started.count(), 1);
        QCOMPARE(started.at(0).at(0).value<quint64>(), gen);
        QCOMPARE(seen, QString("shading..."));
        QTRY_COMPARE(ended.count(), 1);
        QCOMPARE(ended.at(0).at(1).toBool(), true);
        QTRY_VERIFY(!w_->findChild<QLabel*>("statusTask_shading"));
        QVERIFY(cv()->shownImage() != nullptr);
        QVERIFY(doc()->runs().runOutput()->truth.metrics.imageErrorComputed);
    }

    // Shading shows its progress in the status bar and stops at its Cancel:
    // the run keeps its lists and ground truth, no images arrive, the row
    // goes. 1280x720 with the atrium's 1,024 lights: the all-lights image
    // alone takes seconds on either backend, far longer than one 100 ms slice.
    void statusBarCancelsShading() {
        QVERIFY(w_->openBuiltin("atrium"));
        QVERIFY(w_->setParamFromUi("algorithm", "2.5d"));
        w_->setBackend("cpu");
        const quint64 gen = w_->runCulling();
        QVERIFY(waitRun(gen));
        QSignalSpy ended(w_->cullService(), &CullService::shadingEnded);
        pickMode("difference");
        QProgressBar* bar = nullptr;
        QTRY_VERIFY_WITH_TIMEOUT((bar = w_->findChild<QProgressBar*>("statusProgress_shading")) && bar->value() > 0,
                                 lctest::kRunTimeoutMs);
        QVERIFY(bar->isVisible());
        QVERIFY(bar->value() < bar->maximum());
        auto* cancel = w_->findChild<QToolButton*>("statusCancel_shading");
        QVERIFY(cancel && cancel->isVisible());
        QTest::mouseClick(cancel, Qt::LeftButton);
        QTRY_COMPARE_WITH_TIMEOUT(ended.count(), 1, lctest::kRunTimeoutMs);
        QCOMPARE(ended.at(0).at(0).value<quint64>(), gen);
        QCOMPARE(ended.at(0).at(1).toBool(), false);
        QTRY_VERIFY(!w_->findChild<QProgressBar*>("statusProgress_shading"));
        QCOMPARE(doc()->runs().runGeneration(), gen);
        QVERIFY(doc()->runs().runOutput()->shadedAll.empty());
        QVERIFY(doc()->runs().runOutput()->truthComputed);
        QVERIFY(cv()->shownImage() == nullptr);
    }

    // Live drag in a shaded mode: the lists arrive first, then ground truth,
    // then the images of the same generation; the view ends on the newest run.
    void liveShowsListsBeforeImages() {
        openSmall();
        pickMode("difference");
        QVERIFY(waitShaded(w_->runCulling()));
        std::vector<std::pair<quint64, int>> seen; // generation, 0 lists / 1 truth / 2 images
        QObject ctx;
        connect(&doc()->runs(), &RunState::runOutputChanged, &ctx, [&] {
            const auto run = doc()->runs().runOutput();
            seen.push_back({doc()->runs().runGeneration(), !run->shadedAll.empty() ? 2 : run->truthComputed ? 1 : 0});
        });
        w_->setLive(true);
        QVERIFY(waitShaded(w_->cullService()->lastGeneration()));
        seen.clear();
        const glm::dvec3 p = doc()->scene().lights[0].position;
        const int drag = doc()->newDragId();
        doc()->moveLight(0, p + glm::dvec3(0.3, 0, 0), drag); // the handle widget's path
        const quint64 gen = w_->cullService()->lastGeneration();
        QVERIFY(waitShaded(gen));
        std::vector<int> phases;
        for (const auto& [g, phase] : seen)
            if (g == gen) phases.push_back(phase);
        QCOMPARE(phases, (std::vector<int>{0, 1, 2}));
        QVERIFY(cv()->shownImageRun() == doc()->runs().runOutput().get());
        w_->setLive(false);
    }

    // A newer request posted while a run is being shaded cancels that
    // shading: its images are never sent, and the newer run brings its own.
    void newerRequestCancelsShading() {
        CullService service;
        lc::Scene scene = lc::makeBuiltinScene("atrium");
        scene.camera.width = 320;
        scene.camera.height = 180;
        std::vector<std::pair<quint64, bool>> results; // generation, with images
        connect(&service, &CullService::finished, this,
                [&](quint64 g, std::shared_ptr<const lc::RunOutput> out) { results.push_back({g, !out->shadedAll.empty()}); });
        QSignalSpy ended(&service, &CullService::shadingEnded);
        lc::Scene moved = scene;
        moved.lights[0].position.x += 0.5;
        // Posted from the worker thread the moment shading of run 1 starts:
        // deterministic, the request is there before a pixel is shaded.
        bool posted = false;
        connect(service.worker(), &CullWorker::shadingStarted, service.worker(), [&](quint64 g) {
            if (g != 1 || posted) return;
            posted = true;
            CullRequest r;
            r.generation = 2;
            r.scene = std::make_shared<const lc::Scene>(moved);
            r.backend = "cpu";
            r.shade = true;
            service.worker()->post(std::move(r));
        }, Qt::DirectConnection);
        QCOMPARE(service.request(scene, {}, "cpu", "", false, /*shade=*/true), quint64(1));
        QTRY_VERIFY_WITH_TIMEOUT(ended.count() == 2, lctest::kRunTimeoutMs);
        QVERIFY(posted);
        QCOMPARE(ended.at(0).at(0).value<quint64>(), quint64(1));
        QCOMPARE(ended.at(0).at(1).toBool(), false); // cancelled
        QCOMPARE(ended.at(1).at(0).value<quint64>(), quint64(2));
        QCOMPARE(ended.at(1).at(1).toBool(), true);
        QTest::qWait(50);
        const std::vector<std::pair<quint64, bool>> expected = {{1, false}, {2, false}, {2, true}};
        QCOMPARE(results, expected);
    }

    // File > Export diagnostics writes the three PNGs: shaded on the worker
    // when the shown run was not (heat-map mode), and the same files as the CLI's.
    void exportWritesShadedPngs() {
        const QString cli = cliOut("cpu");
        QVERIFY(!cli.isEmpty());
        openSmall();
        QVERIFY(waitRun(w_->runCulling()));
        QVERIFY(doc()->runs().runOutput()->shadedAll.empty());
        const QString dir = tmp_.path() + "/studio-export";
        QVERIFY(lctest::exportAndWait(*w_, dir));
        for (const char* f : kPngOfMode) {
            QImage studio(dir + "/" + f), fromCli(cli + "/" + f);
            QVERIFY2(!studio.isNull(), f);
            QVERIFY(!fromCli.isNull());
            QCOMPARE(studio.convertToFormat(QImage::Format_RGB888), fromCli.convertToFormat(QImage::Format_RGB888));
        }
        const nlohmann::json a = readJson(dir + "/summary.json"), b = readJson(cli + "/summary.json");
        QCOMPARE(a["metrics"]["image_rmse"].get<double>(), b["metrics"]["image_rmse"].get<double>());
        QCOMPARE(a["metrics"]["image_max_error"].get<double>(), b["metrics"]["image_max_error"].get<double>());
        // The shading also reached the view: picking a mode needs no new pass.
        QSignalSpy started(w_->cullService(), &CullService::shadingStarted);
        pickMode("shaded-all");
        QVERIFY(cv()->shownImage() != nullptr);
        QCOMPARE(differingPixels(cv()->shownImage(), cli + "/shaded_all.png"), 0L);
        QTest::qWait(100);
        QCOMPARE(started.count(), 0);
    }

    // The mode is a view setting: it persists (QSettings) into the next window.
    void imageModePersists() {
        pickMode("shaded-all");
        w_.reset();
        init();
        QCOMPARE(cv()->imageMode(), Mode::ShadedAll);
        QVERIFY(w_->action("actionImage_shaded-all")->isChecked());
    }
};

LC_STUDIO_TEST_MAIN(ShadedViewTest)
#include "test_shaded_view.moc"
