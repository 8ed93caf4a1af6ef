// The document's parts (selection, view options, run state, the explained
// selection) as the window and its views use them. What a user would see go
// wrong: a view reading a removed light's index or the old scene's run while
// a change is announced, the Explain panel and the inspector's markers
// disagreeing after a new selection, the toolbar showing another backend or
// Live state than the one the next run uses.
#include "document/document.hpp"
#include "views/camera_view.hpp"
#include "work/cull_worker.hpp"
#include "panels/explain_panel.hpp"
#include "views/inspector_view.hpp"
#include "views/overlay_actors.hpp"
#include "window/main_window.hpp"
#include "studio_test_support.hpp"

#include <QAction>
#include <QComboBox>
#include <QLineEdit>

#include <memory>

using namespace lcui;

class DocumentTest : public QObject {
    Q_OBJECT
    std::unique_ptr<MainWindow> w_;
    Document* doc() const { return w_->document(); }

    bool openSmall() {
        return lctest::openBuiltinWith(*w_, "atrium", {{"width", "320"}, {"height", "180"}});
    }

    // The tile whose lists hold the most lights, and one light its first list holds.
    std::pair<int, int> busyTileAndLight(int skip = 0) const {
        const lc::CullResult& r = doc()->runs().runOutput()->result;
        std::vector<std::pair<std::uint32_t, int>> byLength;
        for (std::uint32_t t = 0; t < r.grid.tileCount(); ++t) byLength.emplace_back(r.listCount[r.listOf(t, -1)], int(t));
        std::sort(byLength.rbegin(), byLength.rend());
        const int tile = byLength.at(std::size_t(skip)).second;
        const std::uint32_t list = r.listOf(std::uint32_t(tile), -1);
        return {tile, int(r.lightIndices[r.listOffset[list]])};
    }

private slots:
    void init() {
        w_ = lctest::makeTestWindow();
        QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
    }
    void cleanup() { w_.reset(); }

    // Removing the selected lights: whoever hears lightsChanged already sees
    // a selection of lights that exist (the inspector and the property panel
    // index the scene with it).
    void removedLightsLeaveTheSelectionFirst() {
        QVERIFY(openSmall());
        const int n = int(doc()->scene().lights.size());
        QVERIFY(n > 3);
        doc()->selection().setSelectedLights({n - 2, n - 1});
        int heard = 0;
        connect(doc(), &Document::lightsChanged, this, [&] {
            ++heard;
            for (int i : doc()->selection().selectedLights()) QVERIFY(i < int(doc()->scene().lights.size()));
        });
        QSignalSpy changed(&doc()->selection(), &Selection::changed);
        doc()->deleteLights({n - 2, n - 1});
        QCOMPARE(heard, 1);
        QCOMPARE(doc()->selection().currentLight(), -1);
        QCOMPARE(changed.count(), 1);
        // Undo brings them back, selected again, and the selection hears of it.
        doc()->undoStack()->undo();
        QCOMPARE(int(doc()->scene().lights.size()), n);
        QCOMPARE(doc()->selection().selectedLights(), (std::vector<int>{n - 2, n - 1}));
        QCOMPARE(changed.count(), 2);
    }

    // A new scene: every part is reset before any of them is announced, so
    // no receiver sees the old run or selection beside the new scene.
    void aNewSceneResetsEveryPartBeforeAnyoneHears() {
        QVERIFY(openSmall());
        QVERIFY(lctest::waitRun(*w_, w_->runCulling(), true));
        const auto [tile, light] = busyTileAndLight();
        doc()->selection().setSelectedTile(tile);
        doc()->selection().setSelectedLights({light});
        QVERIFY(doc()->explained().explanation);
        int heard = 0;
        const auto check = [&] {
            ++heard;
            QVERIFY(!doc()->runs().runOutput());
            QCOMPARE(doc()->selection().selectedTile(), -1);
            QCOMPARE(doc()->selection().currentLight(), -1);
            QVERIFY(!doc()->explained().explanation);
        };
        connect(doc(), &Document::sceneReset, this, check);
        connect(&doc()->selection(), &Selection::changed, this, check);
        connect(&doc()->selection(), &Selection::tileChanged, this, check);
        connect(&doc()->runs(), &RunState::runOutputChanged, this, check);
        QVERIFY(w_->openBuiltin("forest"));
        QCOMPARE(heard, 4);
    }

    // The Explain panel and the inspector's markers show the document's one
    // explanation, and it follows the selection (a cached explanation of the
    // previous tile would be a wrong answer shown with confidence).
    void theExplanationFollowsTheSelection() {
        QVERIFY(openSmall());
        QVERIFY(lctest::waitRun(*w_, w_->runCulling(), true));
        const auto [tileA, lightA] = busyTileAndLight(0);
        const auto [tileB, lightB] = busyTileAndLight(1);
        QVERIFY(tileA != tileB);
        doc()->selection().setSelectedTile(tileA);
        doc()->selection().setSelectedLights({lightA});
        const auto& first = doc()->explained().explanation;
        QVERIFY(first);
        const lc::CullResult& r = doc()->runs().runOutput()->result;
        QCOMPARE(first->list, r.listOf(std::uint32_t(tileA), -1));
        QCOMPARE(int(first->light), lightA);
        QCOMPARE(w_->explainPanel()->explanation()->list, first->list);
        QCOMPARE(w_->inspectorView()->overlays()->explanation()->list, first->list);

        doc()->selection().setSelectedTile(tileB);
        doc()->selection().setSelectedLights({lightB});
        const auto& second = doc()->explained().explanation;
        QVERIFY(second);
        QCOMPARE(second->list, r.listOf(std::uint32_t(tileB), -1));
        QCOMPARE(int(second->light), lightB);
        QCOMPARE(w_->explainPanel()->explanation()->list, second->list);
        QCOMPARE(int(w_->explainPanel()->explanation()->light), lightB);
        QCOMPARE(w_->inspectorView()->overlays()->explanation()->list, second->list);

        // The camera view outlines the tiles whose lists hold the current light.
        QVERIFY(!w_->cameraView()->highlightedTiles().empty());
        const QString tip = w_->cameraView()->tileTooltip(tileB);
        QVERIFY2(!tip.contains("changed since"), qPrintable(tip));

        // An edit makes the run stale: nothing is explained until it runs
        // again, and whoever hears of the removal first already sees that
        // (not the explanation of a light whose index has moved).
        int heard = 0;
        connect(doc(), &Document::lightsChanged, this, [&] {
            ++heard;
            QVERIFY(!doc()->explained().explanation);
        });
        doc()->deleteLights({0});
        QCOMPARE(heard, 1);
        QVERIFY(doc()->runs().runIsStale());
        QVERIFY(!doc()->explained().explanation);
        QVERIFY(!w_->explainPanel()->explanation());
        // Another light picked now: the old run's index for it is another
        // light's, so no tile is outlined as holding it, and a tile's tooltip
        // says its figures are the last run's.
        doc()->selection().setSelectedLights({lightB});
        QVERIFY(w_->cameraView()->highlightedTiles().empty());
        const QString staleTip = w_->cameraView()->tileTooltip(tileB);
        QVERIFY2(staleTip.contains("changed since"), qPrintable(staleTip));
        // Export refuses a stale run before asking for a folder.
        bool asked = false;
        QString refused;
        w_->prompts.savePath = [&](QWidget*, const QString&, const QString&) {
            asked = true;
            return QString();
        };
        w_->prompts.showError = [&](QWidget*, const QString&, const QString& m) { refused = m; };
        w_->action("actionExportDiagnostics")->trigger();
        QVERIFY(!asked);
        QVERIFY2(refused.contains("press F5"), qPrintable(refused));
    }

    // Live re-runs on every change of what to run, but not before a scene is
    // open: settings given first (the studio's --param) are for its first
    // run, and a run of the empty document would log "0 lights".
    void liveRunsNothingBeforeASceneIsOpen() {
        w_->setLive(true);
        QVERIFY(w_->setParamFromUi("cells", "8"));
        doc()->runs().setBackend("cpu");
        QCOMPARE(w_->cullService()->lastGeneration(), quint64(0));
        QVERIFY(openSmall());
        QVERIFY(w_->cullService()->lastGeneration() > 0);
        QVERIFY(lctest::waitRun(*w_, w_->cullService()->lastGeneration()));
        QVERIFY(doc()->runs().runOutput()->lights.size() > 0);
        QCOMPARE(doc()->runs().runOutput()->result.settings.cells, 8u);
        w_->setLive(false);
    }

    // The backend and Live are the document's: the toolbar shows them, a
    // user's pick sets them, and the next run uses what they say.
    void backendAndLiveAreTheDocuments() {
        QVERIFY(openSmall());
        auto* combo = w_->findChild<QComboBox*>("backendCombo");
        QAction* live = w_->action("actionLive");
        QCOMPARE(doc()->runs().backend(), QString("cpu"));
        QCOMPARE(combo->currentText(), QString("cpu"));
        QVERIFY(!live->isChecked());

        // The user checks Live: the document says so, and a run starts.
        QSignalSpy finished(w_.get(), &MainWindow::runFinished);
        live->trigger();
        QVERIFY(doc()->runs().live());
        QVERIFY(w_->isLive());
        QVERIFY(finished.wait(lctest::kRunTimeoutMs));
        QCOMPARE(QString::fromStdString(doc()->runs().runOutput()->result.backend), QString("cpu"));

        // Set from the document (a script, a restored setting): the action follows.
        doc()->runs().setLive(false);
        QVERIFY(!live->isChecked());

        // The device selector typed by the user is the document's too.
        auto* device = w_->findChild<QLineEdit*>("deviceEdit");
        device->setText("0");
        emit device->editingFinished();
        QCOMPARE(doc()->runs().device(), QString("0"));
        doc()->runs().setDevice({});
        QCOMPARE(device->text(), QString());

        if (combo->findText("vulkan") < 0) return; // a build without Vulkan: the CPU is all there is
        combo->setCurrentText("vulkan");
        emit combo->textActivated("vulkan");
        QCOMPARE(doc()->runs().backend(), QString("vulkan"));
        QVERIFY(lctest::waitRun(*w_, w_->runCulling()));
        QCOMPARE(QString::fromStdString(doc()->runs().runOutput()->result.backend), QString("vulkan"));
        doc()->runs().setBackend("cpu");
        QCOMPARE(combo->currentText(), QString("cpu"));
    }
};

LC_STUDIO_TEST_MAIN(DocumentTest)
#include "test_document.moc"
