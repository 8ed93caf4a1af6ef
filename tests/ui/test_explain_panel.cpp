// The Explain panel as a user reaches it: click a tile in the camera view's
// place (the document's tile selection), pick a light in the scene tree, and
// the panel shows lc::explainLight's explanation of that light in that list;
// a light the list lacks but pixels need is shown MISSING, in red.

#include "studio_test_support.hpp"

#include "document.hpp"
#include "explain_panel.hpp"
#include "main_window.hpp"
#include "scene_tree.hpp"

#include "culling/explain.hpp"
#include "culling/ground_truth.hpp"

#include <QDir>
#include <QElapsedTimer>
#include <QLabel>
#include <QPlainTextEdit>
#include <QUndoStack>

using namespace lcui;

class ExplainPanelTest : public QObject {
    Q_OBJECT
    std::unique_ptr<MainWindow> w_;
    Document* doc() const { return w_->document(); }

    bool waitTruth(quint64 generation) {
        QSignalSpy done(w_.get(), &MainWindow::runFinished);
        QElapsedTimer t;
        t.start();
        while (t.elapsed() < 120000) {
            if (doc()->runGeneration() >= generation && doc()->runOutput() && doc()->runOutput()->truthComputed)
                return true;
            done.wait(100);
        }
        return false;
    }

private slots:
    void init() {
        w_ = lctest::makeTestWindow();
        QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
        QVERIFY(w_->openBuiltin("atrium"));
        QVERIFY(w_->setParamFromUi("width", "320"));
        QVERIFY(w_->setParamFromUi("height", "180"));
        doc()->undoStack()->clear();
        QVERIFY(waitTruth(w_->runCulling()));
    }
    void cleanup() {
        doc()->undoStack()->setClean();
        w_.reset();
    }

    void explainsTheSelectedLightInTheSelectedTile() {
        ExplainPanel* panel = w_->explainPanel();
        QVERIFY(panel);
        QVERIFY(!panel->explanation()); // nothing selected yet: a hint
        auto run = doc()->runOutput();
        // The busiest tile and a light listed there, chosen as a user would:
        // the tile in the camera view, the light in the scene tree.
        std::uint32_t tile = 0;
        for (std::uint32_t t = 0; t < run->result.grid.tileCount(); ++t)
            if (run->result.listCount[t] > run->result.listCount[tile]) tile = t;
        const std::uint32_t light = run->result.lightIndices[run->result.listOffset[tile]];
        doc()->setSelectedTile(int(tile));
        w_->sceneTree()->setCurrentIndex(w_->sceneTree()->lightIndex(int(light)));
        QVERIFY(panel->explanation());
        const lc::Explanation expect =
            lc::explainLight(*run, lc::Projection(doc()->scene().camera), tile, light);
        QCOMPARE(panel->explanation()->text(), expect.text());
        QCOMPARE(panel->explanation()->listed, true);
        QVERIFY(panel->textView()->toPlainText().contains("side plane left"));
        auto* verdict = panel->findChild<QLabel*>("explainVerdict");
        QCOMPARE(verdict->text(), QString::fromStdString(expect.verdict));

        // A light far from the tile: rejected, and the panel says by what.
        std::uint32_t far = 0;
        for (std::uint32_t i = 0; i < run->lights.size(); ++i) {
            const auto b = run->result.lightIndices.begin() + run->result.listOffset[tile];
            if (!std::binary_search(b, b + run->result.listCount[tile], i)) {
                far = i;
                break;
            }
        }
        w_->sceneTree()->setCurrentIndex(w_->sceneTree()->lightIndex(int(far)));
        QVERIFY(panel->explanation());
        QCOMPARE(panel->explanation()->listed, false);
        QVERIFY2(verdict->text().contains("rejected by"), qPrintable(verdict->text()));
        QVERIFY(panel->textView()->toPlainText().contains("FAIL"));
        // For a person to look at (docs/STUDIO.md): the window with the panel.
        w_->sceneTree()->setCurrentIndex(w_->sceneTree()->lightIndex(int(light)));
        QDir().mkpath(LC_RENDER_OUT_DIR);
        QVERIFY(w_->grabWindow().save(LC_RENDER_OUT_DIR "/explain_panel.png"));
    }
};

LC_STUDIO_TEST_MAIN(ExplainPanelTest)
#include "test_explain_panel.moc"
