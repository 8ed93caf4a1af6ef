// A custom culling shader in the studio, as a user works with it: Culling >
// Custom shader... picks the file, the run is judged like a built-in one, and
// saving the file in an editor re-runs culling: a flawed edit shows its missed
// lights in the tile inspector (MISSING, in red), a syntax error lands in the
// message log with file and line and leaves the scene alone, and Built-in
// algorithm goes back.

#include "studio_test_support.hpp"

#include <QDockWidget>
#include <QLabel>

#include "document/document.hpp"
#include "panels/explain_panel.hpp"
#include "window/main_window.hpp"
#include "panels/tile_inspector.hpp"

#include "culling/custom/custom_cull.hpp"
#include "culling/scene/scene_io.hpp"

#include <QAction>
#include <QElapsedTimer>
#include <QFile>
#include <QPlainTextEdit>
#include <QProcess>
#include <QTableView>
#include <QUndoStack>

#include <fstream>
#include <sstream>

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

} // namespace

class CustomShaderStudioTest : public QObject {
    Q_OBJECT
    std::unique_ptr<MainWindow> w_;
    QTemporaryDir tmp_;
    Document* doc() const { return w_->document(); }

    // Waits for a run newer than `after` to finish (true) or fail (false).
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
            if (doc()->runs().runGeneration() > after && doc()->runs().runOutput() && doc()->runs().runOutput()->truthComputed) return true;
            done.wait(100);
        }
        return false;
    }
    // Rewrites the watched file as an editor saving it would.
    void save(const QString& path, const std::string& text) {
        std::ofstream(path.toStdString(), std::ios::trunc) << text;
    }

private slots:
    void init() {
        w_ = lctest::makeTestWindow();
        QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
        w_->setBackend("vulkan"); // the custom shader runs on Vulkan; depth too
        QVERIFY(w_->openBuiltin("atrium"));
        // 650 x 368: 40.6 tiles across, so the flawed edit below drifts.
        QVERIFY(w_->setParamFromUi("width", "650"));
        QVERIFY(w_->setParamFromUi("height", "368"));
        doc()->undoStack()->clear();
    }
    void cleanup() {
        doc()->undoStack()->setClean();
        w_.reset();
    }

    void shaderIsPickedRunAndWatched() {
        const QString mine = tmp_.path() + "/mine.comp";
        save(mine, readAll(kExamples + "tiled_fixed.comp"));
        w_->prompts.openPath = [&](QWidget*, const QString&, const QString& filter) {
            return filter.contains("*.hlsl") && filter.contains("*.spv") ? mine : QString();
        };
        quint64 before = doc()->runs().runGeneration();
        w_->action("actionCustomShader")->trigger();
        QCOMPARE(w_->customShaderPath(), mine);
        QString why;
        QVERIFY2(waitRunAfter(before, &why), qPrintable(why));
        auto run = doc()->runs().runOutput();
        QVERIFY(run->custom);
        QCOMPARE(run->truth.metrics.falseNegatives, std::uint64_t(0));
        QCOMPARE(QString::fromStdString(run->custom->layout), QString("fixed:256")); // its first line
        QVERIFY(w_->messageLog()->toPlainText().contains("custom shader " + mine));
        // The built-in algorithm's settings are greyed out, saying why; the grid's stay.
        auto* algorithm = w_->findChild<QWidget*>("param_algorithm");
        QVERIFY(algorithm && !algorithm->isEnabled());
        QVERIFY2(algorithm->toolTip().contains("makes the lists"), qPrintable(algorithm->toolTip()));
        QVERIFY(w_->findChild<QWidget*>("param_tile")->isEnabled());
        QVERIFY(!w_->findChild<QWidget*>("presetCombo")->isEnabled());

        // Save a flawed version: the watcher re-runs, and the misses show.
        std::string flawed = readAll(kExamples + "flawed_tile_edges.comp");
        flawed.replace(flawed.find("fixed:256"), 9, "bitmask"); // no overflow: only the drift misses
        before = doc()->runs().runGeneration();
        save(mine, flawed);
        QVERIFY2(waitRunAfter(before, &why), qPrintable(why));
        run = doc()->runs().runOutput();
        QVERIFY(run->custom);
        QCOMPARE(QString::fromStdString(run->custom->layout), QString("bitmask"));
        QVERIFY(run->truth.metrics.falseNegatives > 0);
        QVERIFY(w_->messageLog()->toPlainText().contains("mine.comp changed: culling again"));
        // The status bar leads with the misses and does not present the
        // efficiency of lists that drop lights as a score.
        const QString fnText = w_->findChild<QLabel*>("statusFalseNegatives")->text();
        QVERIFY2(fnText.startsWith("MISSES LIGHTS: FN "), qPrintable(fnText));
        const QString effText = w_->findChild<QLabel*>("statusEfficiency")->text();
        QVERIFY2(effText.contains("not a score with false negatives") && !effText.contains("optimum"),
                 qPrintable(effText));
        // The tile of the first located miss shows it as MISSING, in red.
        const auto missed = lc::locateFalseNegatives(*run, lc::Projection(doc()->scene().camera));
        QVERIFY(!missed.empty());
        doc()->selection().setSelectedTile(int(missed[0].tile));
        TileInspector* ti = w_->tileInspector();
        bool shown = false;
        for (int r = 0; r < ti->model()->rowCount(); ++r) {
            const QModelIndex verdict = ti->model()->index(r, TileLightsModel::ColVerdict);
            const QModelIndex light = ti->model()->index(r, TileLightsModel::ColLight);
            if (light.data().toUInt() == missed[0].light && verdict.data().toString() == "MISSING") {
                shown = true;
                QCOMPARE(verdict.data(Qt::BackgroundRole).value<QBrush>().color(), QColor(200, 40, 40));
            }
        }
        QVERIFY2(shown, "the missed light is not listed as MISSING in the tile inspector");

        // Culling > Next miss (F8) walks the misses: tile, light and list
        // selected, Explain shown on it with MISSING; Previous goes back.
        auto* explainDock = w_->findChild<QDockWidget*>("explainDock");
        explainDock->hide();
        doc()->selection().setSelectedTile(-1);
        w_->action("actionNextMiss")->trigger(); // F8 (test_studio checks the binding)
        QCOMPARE(doc()->selection().selectedTile(), int(missed[0].tile));
        QCOMPARE(doc()->selection().currentLight(), int(missed[0].light));
        QCOMPARE(doc()->selection().explainedList(), int(missed[0].list));
        QVERIFY(explainDock->isVisible());
        QVERIFY(w_->explainPanel()->explanation());
        QCOMPARE(w_->explainPanel()->explanation()->light, missed[0].light);
        QVERIFY2(QString::fromStdString(w_->explainPanel()->explanation()->verdict).startsWith("MISSING"),
                 w_->explainPanel()->explanation()->verdict.c_str());
        QVERIFY(w_->messageLog()->toPlainText().contains(
            QString("miss 1 of %1: light %2").arg(missed.size()).arg(missed[0].light)));
        QVERIFY(w_->messageLog()->toPlainText().contains("cause: culling test"));
        QVERIFY(missed.size() > 2); // the drift misses lights in several tiles: a walk to test
        w_->action("actionNextMiss")->trigger();
        QCOMPARE(doc()->selection().selectedTile(), int(missed[1].tile));
        QCOMPARE(doc()->selection().currentLight(), int(missed[1].light));
        w_->action("actionPreviousMiss")->trigger();
        QCOMPARE(doc()->selection().selectedTile(), int(missed[0].tile));
        w_->action("actionPreviousMiss")->trigger(); // wraps to the last
        QCOMPARE(doc()->selection().selectedTile(), int(missed.back().tile));

        // A syntax error: the run fails with file and line, the scene stays.
        const std::string sceneBefore = lc::serializeScene(doc()->scene());
        before = doc()->runs().runGeneration();
        std::string broken = readAll(kExamples + "tiled_fixed.comp");
        broken.replace(broken.find("void main() {"), 13, "void main() { undeclaredThing = 1;");
        save(mine, broken);
        QVERIFY(!waitRunAfter(before, &why));
        QVERIFY2(why.contains("mine.comp:") && why.contains("compile error"), qPrintable(why));
        QVERIFY(w_->messageLog()->toPlainText().contains("compile error"));
        QCOMPARE(lc::serializeScene(doc()->scene()), sceneBefore);
        // The flawed shader's run stays on screen: the status bar says it is
        // not the run of the shader now chosen.
        auto* times = w_->findChild<QLabel*>("statusTimes");
        QVERIFY(times);
        QVERIFY2(times->text().startsWith(QString("run %1 failed, showing run %2 (custom shader)")
                                              .arg(doc()->runs().runGeneration() + 1)
                                              .arg(doc()->runs().runGeneration())),
                 qPrintable(times->text()));

        // Back to the built-in algorithm.
        before = doc()->runs().runGeneration();
        w_->action("actionBuiltinAlgorithm")->trigger();
        QVERIFY(w_->customShaderPath().isEmpty());
        QVERIFY2(waitRunAfter(before, &why), qPrintable(why));
        QVERIFY(!doc()->runs().runOutput()->custom);
        QVERIFY2(!times->text().contains("failed"), qPrintable(times->text()));
        QVERIFY(w_->findChild<QWidget*>("param_algorithm")->isEnabled());
        QVERIFY(!w_->findChild<QWidget*>("param_algorithm")->toolTip().contains("makes the lists"));
    }

    // git checkout and some editors delete the file and write it anew: the
    // watch follows it back. A save (truncate, then write) is one run.
    void deletedAndWrittenAgainIsFollowed() {
        const QString mine = tmp_.path() + "/back.comp";
        save(mine, readAll(kExamples + "tiled_fixed.comp"));
        w_->prompts.openPath = [&](QWidget*, const QString&, const QString&) { return mine; };
        quint64 before = doc()->runs().runGeneration();
        w_->action("actionCustomShader")->trigger();
        QString why;
        QVERIFY2(waitRunAfter(before, &why), qPrintable(why));
        QCOMPARE(doc()->runs().runOutput()->truth.metrics.falseNegatives, std::uint64_t(0));

        QVERIFY(QFile::remove(mine));
        QTRY_VERIFY_WITH_TIMEOUT(w_->messageLog()->toPlainText().contains("back.comp is gone"), 5000);
        std::string flawed = readAll(kExamples + "flawed_tile_edges.comp");
        flawed.replace(flawed.find("fixed:256"), 9, "bitmask");
        before = doc()->runs().runGeneration();
        save(mine, flawed);
        QVERIFY2(waitRunAfter(before, &why), qPrintable(why));
        QVERIFY(doc()->runs().runOutput()->truth.metrics.falseNegatives > 0);
        QCOMPARE(doc()->runs().runGeneration(), before + 1);
        QTest::qWait(800); // no second run for the same save
        QCOMPARE(doc()->runs().runGeneration(), before + 1);

        // And later saves in place are followed as before.
        before = doc()->runs().runGeneration();
        save(mine, readAll(kExamples + "tiled_fixed.comp"));
        QVERIFY2(waitRunAfter(before, &why), qPrintable(why));
        QCOMPARE(doc()->runs().runOutput()->truth.metrics.falseNegatives, std::uint64_t(0));

        // Saved with a settings line it cannot use: nothing runs, and the
        // status bar says the figures are the earlier version's until a
        // good save.
        before = doc()->runs().runGeneration();
        std::string badLine = readAll(kExamples + "tiled_fixed.comp");
        badLine.replace(badLine.find("fixed:256"), 9, "fixed:zero");
        save(mine, badLine);
        QTRY_VERIFY_WITH_TIMEOUT(w_->messageLog()->toPlainText().contains("fixed:zero"), 5000);
        auto* times = w_->findChild<QLabel*>("statusTimes");
        QVERIFY2(times->text().startsWith(QString("back.comp refused, showing run %1 (custom shader)").arg(before)),
                 qPrintable(times->text()));
        QVERIFY2(times->toolTip().contains("fixed:zero"), qPrintable(times->toolTip()));
        QCOMPARE(doc()->runs().runGeneration(), before);
        save(mine, readAll(kExamples + "tiled_fixed.comp"));
        QVERIFY2(waitRunAfter(before, &why), qPrintable(why));
        QVERIFY2(!times->text().contains("refused"), qPrintable(times->text()));
    }

    // Lists with a light twice and an index past the light count lose no
    // light, but `run` fails them: the status bar and the log say so.
    void duplicateAndInvalidIndicesAreShown() {
        const QString bad = QStringLiteral(LC_TEST_DATA_DIR) + "/custom/out_of_range.comp";
        w_->prompts.openPath = [&](QWidget*, const QString&, const QString&) { return bad; };
        const quint64 before = doc()->runs().runGeneration();
        w_->action("actionCustomShader")->trigger();
        QString why;
        QVERIFY2(waitRunAfter(before, &why), qPrintable(why));
        const auto run = doc()->runs().runOutput();
        QVERIFY(run->custom && run->custom->duplicateIndices > 0 && run->custom->invalidIndices > 0);
        const QString fn = w_->findChild<QLabel*>("statusFalseNegatives")->text();
        QVERIFY2(fn.contains(QString("%1 invalid indices").arg(run->custom->invalidIndices)) &&
                     fn.contains(QString("%1 duplicate indices").arg(run->custom->duplicateIndices)),
                 qPrintable(fn));
        QVERIFY(w_->messageLog()->toPlainText().contains(
            QString("duplicate indices %1").arg(run->custom->duplicateIndices)));
    }

    // As the CLI: a preset beside --shader would not cull (the shader does),
    // so the studio refuses the pair instead of showing the preset's grid.
    void startingWithAShaderAndAPresetIsRefused() {
        QProcess studio;
        studio.start(LC_STUDIO_PATH, {"--shader", kExamples + "tiled_fixed.comp", "--preset", "godot-4", "--quit"});
        QVERIFY(studio.waitForFinished(lctest::kRunTimeoutMs));
        const QString err = QString::fromUtf8(studio.readAllStandardError());
        QCOMPARE(studio.exitCode(), 2);
        QVERIFY2(err.contains("--preset: has no effect with --shader"), qPrintable(err));
    }

    void badFirstLineIsRefusedAndShown() {
        const QString bad = tmp_.path() + "/bad.comp";
        save(bad, "// lightcull: --layout fixed:zero\n#version 450\nvoid main() {}\n");
        QString shown;
        w_->prompts.showError = [&](QWidget*, const QString&, const QString& m) { shown = m; };
        QVERIFY(!w_->setCustomShader(bad));
        QVERIFY2(shown.contains("bad.comp:1:") && shown.contains("fixed:zero"), qPrintable(shown));
        QVERIFY(w_->customShaderPath().isEmpty());
    }
};

LC_STUDIO_TEST_MAIN(CustomShaderStudioTest)
#include "test_custom_shader_studio.moc"
