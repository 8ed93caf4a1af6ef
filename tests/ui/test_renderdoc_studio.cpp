// RenderDoc in the studio, as a user works with it (real RenderDoc 1.24 from
// Debian, lavapipe with the validation layer): Culling > Capture in
// RenderDoc... writes a capture of the studio's own culling with a flawed
// custom shader; File > Open RenderDoc capture... reads it back through the
// dialog (the path typed, the culling dispatch found among the capture's,
// its bindings listed, the depth and lights previewed before anything is
// culled), and the opened frame gives the run the shader gave: the same
// lists, the same misses, walked with Next miss and explained. Edits to the
// lights are judged against the capture's lists; Built-in algorithm culls on
// the capture's depth; a bad capture or description is one line in the
// dialog and the scene stays.

#include "studio_test_support.hpp"

#include "document/document.hpp"
#include "document/miss_navigator.hpp"
#include "panels/capture_dialog.hpp"
#include "panels/explain_panel.hpp"
#include "window/main_window.hpp"

#include "culling/capture/capture_frame.hpp"
#include "culling/custom/custom_cull.hpp"
#include "culling/diagnostics/explain.hpp"
#include "culling/scene/scene_io.hpp"

#include <QComboBox>
#include <QDialogButtonBox>
#include <QLabel>
#include <QLineEdit>
#include <QPlainTextEdit>
#include <QProcess>
#include <QPushButton>
#include <QTableWidget>
#include <QUndoStack>

#include <fstream>
#include <set>
#include <sstream>
#include <tuple>

using namespace lcui;

namespace {

constexpr int kWaitMs = 120000;
const QString kExamples = QStringLiteral(LC_SOURCE_DIR) + "/resources/culling-examples/";

std::string readAll(const QString& path) {
    std::ifstream in(path.toStdString());
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}
void writeText(const QString& path, const std::string& text) { std::ofstream(path.toStdString()) << text; }

// The custom-culling contract's bindings as a capture description
// (docs/RENDERDOC.md): what a user writes for the tool's own capture.
std::string contractDescription(const std::string& layout) {
    return R"({"lights": {"binding": "0.3", "stride": 32, "position": 0, "radius": 12, "spot_axis": 16, "spot_angle": 28},
 "camera": {"binding": "0.0", "projection": 96}, "depth": {"binding": "0.1"},
 "lists": {"layout": ")" + layout + R"(", "binding": "0.4", "rule": "tile"}})";
}

// A run's lists, and its misses as (list, light).
std::vector<std::vector<std::uint32_t>> listsOf(const lc::RunOutput& r) {
    std::vector<std::vector<std::uint32_t>> out;
    for (std::size_t i = 0; i < r.result.listCount.size(); ++i) {
        const auto* b = r.result.lightIndices.data() + r.result.listOffset[i];
        out.emplace_back(b, b + r.result.listCount[i]);
    }
    return out;
}
std::set<std::pair<std::uint32_t, std::uint32_t>> missesOf(const lc::RunOutput& r, const lc::Camera& cam) {
    std::set<std::pair<std::uint32_t, std::uint32_t>> out;
    for (const auto& m : lc::locateFalseNegatives(r, lc::Projection(cam))) out.insert({m.list, m.light});
    return out;
}

// Types `text` into a line edit and presses Return, as a person does.
void typeInto(QLineEdit* edit, const QString& text) {
    edit->setFocus();
    edit->selectAll();
    QTest::keyClicks(edit, text);
    QTest::keyClick(edit, Qt::Key_Return);
}

} // namespace

class RenderDocStudioTest : public QObject {
    Q_OBJECT
    std::unique_ptr<MainWindow> w_;
    QTemporaryDir tmp_;
    Document* doc() const { return w_->document(); }

    bool waitRunAfter(quint64 after, QString* failure = nullptr) {
        QSignalSpy done(w_.get(), &MainWindow::runFinished);
        QSignalSpy failed(w_.get(), &MainWindow::runFailed);
        QElapsedTimer t;
        t.start();
        while (t.elapsed() < kWaitMs) {
            for (const auto& f : failed)
                if (f.at(0).toULongLong() > after) {
                    if (failure) *failure = f.at(1).toString();
                    return false;
                }
            if (doc()->runs().runGeneration() > after && doc()->runs().runOutput() &&
                doc()->runs().runOutput()->truthComputed)
                return true;
            done.wait(100);
        }
        return false;
    }
    std::shared_ptr<const lc::RunOutput> runAndWait(const std::function<void()>& action) {
        const quint64 before = doc()->runs().runGeneration();
        action();
        QString why;
        if (!waitRunAfter(before, &why)) {
            qWarning("run failed: %s", qPrintable(why));
            return nullptr;
        }
        return doc()->runs().runOutput();
    }

private slots:
    void initTestCase() {
        qputenv("LIGHTCULL_VALIDATION", "1");
        qputenv("LIGHTCULL_CLI", LC_CLI_PATH); // the tests run beside neither the studio nor the CLI
    }
    void init() {
        w_ = lctest::makeTestWindow();
        QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
        w_->setBackend("vulkan");
        QVERIFY(w_->openBuiltin("atrium"));
        // 650 x 368: 40.6 tiles across, where flawed_tile_edges drifts.
        QVERIFY(w_->setParamFromUi("width", "650"));
        QVERIFY(w_->setParamFromUi("height", "368"));
        doc()->undoStack()->clear();
    }
    void cleanup() {
        doc()->undoStack()->setClean();
        w_.reset();
    }

    void captureTheStudiosRunThenJudgeItFromTheCapture() {
        // The studio culls with a flawed shader (bitmask: no overflow, only
        // the drift's misses).
        const QString shader = tmp_.path() + "/mine.comp";
        std::string flawed = readAll(kExamples + "flawed_tile_edges.comp");
        flawed.replace(flawed.find("fixed:256"), 9, "bitmask");
        writeText(shader, flawed);
        auto own = runAndWait([&] { QVERIFY(w_->setCustomShader(shader)); });
        QVERIFY(own && own->custom);
        const lc::Camera camera = doc()->scene().camera;
        const auto ownMisses = missesOf(*own, camera);
        QVERIFY(ownMisses.size() > 2);

        // Culling > Capture in RenderDoc...
        const QString rdc = tmp_.path() + "/frame.rdc";
        w_->prompts.savePath = [&](QWidget*, const QString& caption, const QString& filter) {
            return caption.contains("RenderDoc") && filter.contains("*.rdc") ? tmp_.path() + "/frame" : QString();
        };
        w_->action("actionCaptureRenderDoc")->trigger(); // ".rdc" added to the name given
        QVERIFY2(QFileInfo(rdc).size() > 0, qPrintable(w_->messageLog()->toPlainText()));
        QVERIFY(w_->messageLog()->toPlainText().contains("wrote RenderDoc capture " + rdc));

        // File > Open RenderDoc capture..., driven as a person would.
        const QString describe = tmp_.path() + "/describe.json";
        writeText(describe, contractDescription("bitmask"));
        QString chosenDispatch, previewText;
        int bindingRows = 0;
        bool depthShown = false, openEnabledBefore = true;
        w_->prompts.execDialog = [&](QDialog& d) {
            auto* dlg = qobject_cast<CaptureDialog*>(&d);
            if (!dlg) return int(QDialog::Rejected);
            dlg->show();
            auto* open = dlg->findChild<QDialogButtonBox*>()->button(QDialogButtonBox::Open);
            openEnabledBefore = open->isEnabled();
            typeInto(dlg->findChild<QLineEdit*>("capturePath"), rdc);
            chosenDispatch = dlg->findChild<QComboBox*>("dispatch")->currentText();
            auto* table = dlg->findChild<QTableWidget*>("bindings");
            bindingRows = table->rowCount();
            typeInto(dlg->findChild<QLineEdit*>("descriptionPath"), describe);
            previewText = dlg->findChild<QPlainTextEdit*>("previewText")->toPlainText();
            const QPixmap depth = dlg->findChild<QLabel*>("depthPreview")->pixmap(Qt::ReturnByValue);
            depthShown = !depth.isNull() && depth.toImage().pixelColor(depth.width() / 2, depth.height() / 2) !=
                                                QColor(0, 0, 0);
            // For a person to look at (the render tests' output folder).
            QDir().mkpath(LC_RENDER_OUT_DIR);
            dlg->grab().save(QString(LC_RENDER_OUT_DIR) + "/capture_dialog.png");
            if (!open->isEnabled()) return int(QDialog::Rejected);
            QTest::mouseClick(open, Qt::LeftButton);
            return dlg->result();
        };
        // (The test window does not run on open: runOnOpen is off.)
        auto judged = runAndWait([&] {
            w_->action("actionOpenCapture")->trigger();
            w_->runCulling();
        });
        QVERIFY(!openEnabledBefore); // nothing to open before a preview
        QVERIFY2(chosenDispatch.contains("custom.cull"), qPrintable(chosenDispatch));
        QVERIFY2(bindingRows >= 5, qPrintable(QString::number(bindingRows)));
        QVERIFY2(previewText.contains(QString("lights: %1 (").arg(own->lights.size())), qPrintable(previewText));
        QVERIFY2(previewText.contains("depth: 650x368"), qPrintable(previewText));
        QVERIFY(depthShown);
        QVERIFY(judged && judged->custom);
        QVERIFY(w_->captureFrame() && w_->cullsCaptureLists());
        QVERIFY(w_->action("actionCaptureLists")->isEnabled());
        QVERIFY(w_->customShaderPath().isEmpty());
        QVERIFY(QString::fromStdString(judged->depthFrom).startsWith("capture " + rdc + " event "));
        QCOMPARE(doc()->scene().lights.size(), own->lights.size());
        QVERIFY(doc()->scene().meshes.empty());
        QVERIFY(w_->messageLog()->toPlainText().contains("read lights: "));
        QVERIFY(w_->messageLog()->toPlainText().contains("lists of capture " + rdc));

        // The capture's verdict is the run's: same lists, same misses.
        QCOMPARE(listsOf(*judged), listsOf(*own));
        QCOMPARE(judged->truth.metrics.falseNegatives, own->truth.metrics.falseNegatives);
        const lc::Camera capCam = doc()->scene().camera;
        const auto capMisses = missesOf(*judged, capCam);
        QCOMPARE(capMisses, ownMisses);

        // Next miss walks them, Explain on each.
        w_->action("actionNextMiss")->trigger();
        const auto located = lc::locateFalseNegatives(*judged, lc::Projection(capCam));
        const auto first = located.front();
        QCOMPARE(doc()->selection().selectedTile(), int(first.tile));
        QCOMPARE(doc()->selection().currentLight(), int(first.light));
        QVERIFY(w_->explainPanel()->explanation());
        QVERIFY2(QString::fromStdString(w_->explainPanel()->explanation()->verdict).startsWith("MISSING"),
                 w_->explainPanel()->explanation()->verdict.c_str());

        // The studio started on the capture (--capture) shows the same first miss.
        {
            QProcess studio;
            studio.start(LC_STUDIO_PATH, {"--capture", rdc, "--dispatch", "custom.cull", "--describe", describe,
                                          "--backend", "vulkan", "--first-miss", "--quit"});
            QVERIFY(studio.waitForFinished(kWaitMs));
            const QString said = QString::fromLocal8Bit(studio.readAllStandardOutput());
            QVERIFY2(said.contains(QString("miss 1 of %1: light %2 ").arg(located.size()).arg(first.light)),
                     qPrintable(said + studio.readAllStandardError()));
            studio.start(LC_STUDIO_PATH, {"--capture", rdc, "--quit"});
            QVERIFY(studio.waitForFinished(kWaitMs));
            QCOMPARE(studio.exitCode(), 2);
            QVERIFY(studio.readAllStandardError().contains("--capture, --dispatch and --describe go together"));
        }

        // A light edited is judged against the capture's lists: grown to
        // cover the whole view, every list that lacks it misses it.
        const int grown = int(first.light);
        lc::PointLight big = doc()->scene().lights[std::size_t(grown)];
        big.explicitRadius = 1e4;
        auto edited = runAndWait([&] { doc()->setLight(grown, big); w_->runCulling(); });
        QVERIFY(edited && edited->custom);
        QCOMPARE(listsOf(*edited), listsOf(*own)); // the capture's lists, unchanged
        QVERIFY(edited->truth.metrics.falseNegatives > judged->truth.metrics.falseNegatives);

        // The built-in algorithm on the capture's depth: no misses.
        auto builtin = runAndWait([&] { w_->action("actionBuiltinAlgorithm")->trigger(); });
        QVERIFY(builtin && !builtin->custom);
        QVERIFY(!w_->cullsCaptureLists());
        QVERIFY(QString::fromStdString(builtin->depthFrom).startsWith("capture "));
        QCOMPARE(builtin->truth.metrics.falseNegatives, std::uint64_t(0));
        // ... and back to the capture's lists.
        auto back = runAndWait([&] { w_->action("actionCaptureLists")->trigger(); });
        QVERIFY(back && back->custom);
        QCOMPARE(back->truth.metrics.falseNegatives, edited->truth.metrics.falseNegatives);

        // A camera that is not the capture's is refused: its depth is for
        // the capture's view.
        QString why;
        quint64 before = doc()->runs().runGeneration();
        QVERIFY(w_->setParamFromUi("width", "640"));
        w_->runCulling();
        QVERIFY(!waitRunAfter(before, &why));
        QVERIFY2(why.contains("the camera is not the capture's"), qPrintable(why));
        doc()->undoStack()->undo();

        // Capturing the tool's passes of a capture's scene is refused.
        QString refused;
        w_->prompts.showError = [&](QWidget*, const QString&, const QString& m) { refused = m; };
        QVERIFY(!w_->captureInRenderDoc(tmp_.path() + "/again.rdc"));
        QVERIFY2(refused.contains("RenderDoc capture's"), qPrintable(refused));
        QVERIFY(!QFileInfo::exists(tmp_.path() + "/again.rdc"));

        // Another scene forgets the capture.
        w_->prompts.askUnsaved = [](QWidget*, const QString&) { return QMessageBox::Discard; }; // the edit
        QVERIFY(w_->openBuiltin("atrium"));
        QVERIFY(!w_->captureFrame());
        QVERIFY(!w_->action("actionCaptureLists")->isEnabled());
    }

    void badCaptureAndDescriptionAreOneLineInTheDialog() {
        const std::string sceneBefore = lc::serializeScene(doc()->scene());
        const QString notRdc = tmp_.path() + "/not.rdc";
        writeText(notRdc, "this is not a capture\n");
        QString captureError;
        bool openEnabled = true;
        w_->prompts.execDialog = [&](QDialog& d) {
            auto* dlg = qobject_cast<CaptureDialog*>(&d);
            dlg->show();
            typeInto(dlg->findChild<QLineEdit*>("capturePath"), notRdc);
            captureError = dlg->errorText();
            openEnabled = dlg->findChild<QDialogButtonBox*>()->button(QDialogButtonBox::Open)->isEnabled();
            return int(QDialog::Rejected);
        };
        w_->action("actionOpenCapture")->trigger();
        QVERIFY2(captureError.contains(notRdc) && !captureError.contains('\n'), qPrintable(captureError));
        QVERIFY(!openEnabled);
        QCOMPARE(lc::serializeScene(doc()->scene()), sceneBefore);

        // A description with a field past the light struct: its JSON path.
        const QString rdc = tmp_.path() + "/own.rdc";
        QVERIFY(w_->captureInRenderDoc(rdc)); // the built-in algorithm's passes
        const QString describe = tmp_.path() + "/bad.json";
        writeText(describe, R"({"lights": {"binding": "lc.lights", "stride": 16, "position": 0, "radius": 16},
 "camera": {"fov_y": 60}, "depth": {"binding": "0.0"}, "lists": {"layout": "fixed:64", "binding": "0.1"}})");
        QString shown;
        w_->prompts.showError = [&](QWidget*, const QString&, const QString& m) { shown = m; };
        QVERIFY(!w_->openCapture(rdc, "light lists", describe));
        QVERIFY2(shown.contains("bad.json") && shown.contains("lights.radius"), qPrintable(shown));
        QCOMPARE(lc::serializeScene(doc()->scene()), sceneBefore);
        QVERIFY(!w_->captureFrame());
    }
};

LC_STUDIO_TEST_MAIN(RenderDocStudioTest)

#include "test_renderdoc_studio.moc"
