// The engine limits in the studio, as a user works with them: the Limits
// toolbar's Engine preset sets the culling as the engine does (and shows
// "(none)" once a setting is changed), a run under a cap counts the misses by
// cause, View > Heat map > Over-full lists draws only the over-full tiles in
// orange, and Explain says "dropped: list full (cap N)" for a light the cap
// dropped. The screenshots are written for a person to look at.

#include "studio_test_support.hpp"

#include "views/camera_view.hpp"
#include "document/document.hpp"
#include "panels/explain_panel.hpp"
#include "window/main_window.hpp"
#include "panels/scene_tree.hpp"

#include "culling/diagnostics/explain.hpp"
#include "culling/diagnostics/overlays.hpp"

#include <QAction>
#include <QComboBox>
#include <QFileInfo>
#include <QProcess>
#include <QLabel>
#include <QSpinBox>
#include <QToolBar>
#include <QToolButton>

#include <cmath>

using namespace lcui;

namespace {

// Pixels of `img` in the overlay's orange (hue about 30 degrees, saturated).
int orangePixels(const QImage& img) {
    int n = 0;
    for (int y = 0; y < img.height(); ++y)
        for (int x = 0; x < img.width(); ++x) {
            const QColor c = img.pixelColor(x, y).toHsv();
            if (c.hsvSaturation() > 120 && c.value() > 120 && c.hsvHue() >= 15 && c.hsvHue() <= 45) ++n;
        }
    return n;
}

} // namespace

class LimitsStudioTest : public QObject {
    Q_OBJECT
    std::unique_ptr<MainWindow> w_;
    Document* doc() const { return w_->document(); }
    QComboBox* presetCombo() const { return w_->findChild<QComboBox*>("presetCombo"); }

private slots:
    void init() {
        w_ = lctest::makeTestWindow();
        QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
        QVERIFY(lctest::openBuiltinWith(*w_, "atrium", {{"width", "320"}, {"height", "180"}}));
    }
    void cleanup() { w_.reset(); }

    void presetSetsTheCullingAndShowsNoneOnceChanged() {
        QComboBox* combo = presetCombo();
        QVERIFY(combo);
        QCOMPARE(combo->currentText(), QString("(none)"));
        // The Limits row is visible and nothing on it hides behind an arrow.
        auto* bar = w_->findChild<QToolBar*>("limitsToolbar");
        QVERIFY(bar && bar->isVisible());
        auto* ext = bar->findChild<QToolButton*>("qt_toolbar_ext_button");
        QVERIFY(!ext || !ext->isVisible());

        QVERIFY(w_->setPresetFromUi("threejs"));
        QCOMPARE(combo->currentText(), QString("threejs"));
        const lc::CullSettings& s = doc()->runs().settings();
        QVERIFY(s.algorithm == lc::Algorithm::Naive);
        QCOMPARE(s.cap, 8u);
        QCOMPARE(s.maxLights, 1024u);
        QCOMPARE(doc()->scene().camera.tileSize, 32u); // a camera edit: undoable
        QCOMPARE(w_->findChild<QSpinBox*>("param_cap")->value(), 8);
        QCOMPARE(w_->findChild<QComboBox*>("param_algorithm")->currentText(), QString("naive"));

        // A setting changed by hand: the settings are no longer the preset's.
        QVERIFY(w_->setParamFromUi("cap", "4"));
        QCOMPARE(doc()->runs().settings().cap, 4u);
        QCOMPARE(combo->currentText(), QString("(none)"));
        // Back to exactly the preset's: it shows again.
        QVERIFY(w_->setParamFromUi("cap", "8"));
        QCOMPARE(combo->currentText(), QString("threejs"));
    }

    void overfullTilesAreDrawnAndExplained() {
        QVERIFY(w_->setParamFromUi("algorithm", "minmax"));
        QVERIFY(w_->setParamFromUi("cap", "3"));
        QVERIFY(lctest::waitRun(*w_, w_->runCulling(), true));
        auto run = doc()->runs().runOutput();
        QVERIFY(run);
        const lc::ListLimits& lim = run->result.limits;
        QVERIFY(!lim.overflowLists.empty());
        const lc::Metrics& m = run->truth.metrics;
        QVERIFY(m.falseNegativesListFull > 0);
        QCOMPARE(m.falseNegatives, m.falseNegativesListFull); // the test itself misses nothing
        // The status bar's FN counts them, by cause.
        const QString fn = w_->findChild<QLabel*>("statusFalseNegatives")->text();
        QVERIFY2(fn.contains(QString("FN %1 (test 0, list full %1, light limit 0)").arg(m.falseNegatives)), qPrintable(fn));

        // View > Heat map > Over-full lists: only over-full tiles, in orange.
        CameraView* v = w_->cameraView();
        v->renderNow();
        const int orangeBefore = orangePixels(v->grabFramebuffer());
        QAction* overflow = w_->findChild<QAction*>("actionHeat_overflow");
        QVERIFY(overflow);
        overflow->trigger();
        QCoreApplication::processEvents();
        v->renderNow();
        const QImage shot = v->grabFramebuffer();
        const int orange = orangePixels(shot);
        QVERIFY2(orange > orangeBefore + 500, qPrintable(QString("orange pixels %1, before %2").arg(orange).arg(orangeBefore)));
        QDir().mkpath(LC_RENDER_OUT_DIR);
        QVERIFY(shot.save(QString(LC_RENDER_OUT_DIR) + "/limits_overflow_heat.png"));
        QVERIFY(w_->grab().save(QString(LC_RENDER_OUT_DIR) + "/limits_studio.png"));
        // Every tile drawn is over-full: the heat is NaN (not drawn) elsewhere.
        const std::vector<double> heat = lc::tileHeat(*run, lc::HeatMode::Overflow);
        std::size_t drawn = 0;
        for (double h : heat) drawn += !std::isnan(h);
        std::size_t overTiles = 0;
        for (std::uint32_t t = 0; t < run->result.grid.tileCount(); ++t)
            overTiles += lim.overflowIndex(t) >= 0;
        QCOMPARE(drawn, overTiles);

        // Explain, on a light the cap dropped from a tile where a pixel needs it.
        const std::vector<lc::MissedLight> missed = lc::locateFalseNegatives(*run, lc::Projection(doc()->scene().camera));
        QVERIFY(!missed.empty());
        QVERIFY(missed.front().cause == lc::MissCause::ListFull);
        doc()->selection().setSelectedTile(int(missed.front().tile));
        w_->sceneTree()->setCurrentIndex(w_->sceneTree()->lightIndex(int(missed.front().light)));
        ExplainPanel* panel = w_->explainPanel();
        QVERIFY(panel->explanation());
        auto* verdict = panel->findChild<QLabel*>("explainVerdict");
        QVERIFY2(verdict->text().contains("dropped: list full (cap 3)"), qPrintable(verdict->text()));
    }

    // lightcull-studio --preset NAME: set once the scene is open, --param
    // beside it winning; an unknown name is one line and exit 2.
    void presetOnTheCommandLine() {
        QTemporaryDir dir;
        const QString shot = dir.path() + "/preset.png";
        QProcess p;
        p.start(LC_STUDIO_PATH, {"--builtin", "atrium", "--backend",
                                 "cpu", "--preset", "threejs", "--param", "cap=4", "--screenshot", shot, "--quit"});
        QVERIFY(p.waitForFinished(120000));
        QCOMPARE(p.exitCode(), 0);
        QVERIFY(QFileInfo(shot).size() > 0);
        p.start(LC_STUDIO_PATH, {"--builtin", "atrium", "--preset", "unity", "--quit"});
        QVERIFY(p.waitForFinished(60000));
        QCOMPARE(p.exitCode(), 2);
        const QString err = QString::fromUtf8(p.readAllStandardError());
        QVERIFY2(err.contains("--preset") && err.contains("unknown preset 'unity'"), qPrintable(err));
    }
};

LC_STUDIO_TEST_MAIN(LimitsStudioTest)
#include "test_limits_studio.moc"
