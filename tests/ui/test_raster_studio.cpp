// The raster algorithm in the studio, as a user works with it: picking
// `raster` in the Algorithm box shows its proxy settings on the second row
// (and nothing hides behind a toolbar arrow), typing an overfit of 1 into
// the Overfit box gives the inscribed proxy's misses, Next miss + Explain name
// the proxy's coverage as the failed step, Overfit auto brings them to 0, and
// another algorithm hides the settings again. Screenshots for a person.

#include "studio_test_support.hpp"

#include "document/document.hpp"
#include "panels/explain_panel.hpp"
#include "views/camera_view.hpp"
#include "window/main_window.hpp"

#include <QAction>
#include <QCheckBox>
#include <QComboBox>
#include <QLineEdit>
#include <QSpinBox>
#include <QPlainTextEdit>
#include <QToolBar>
#include <QToolButton>

using namespace lcui;

class RasterStudioTest : public QObject {
    Q_OBJECT
    std::unique_ptr<MainWindow> w_;
    Document* doc() const { return w_->document(); }

    // A toolbar's arrow (the overflow menu) is shown: something is hidden.
    static bool overflows(QToolBar* bar) {
        auto* ext = bar->findChild<QToolButton*>("qt_toolbar_ext_button");
        return ext && ext->isVisible();
    }

private slots:
    void init() {
        w_ = lctest::makeTestWindow();
        QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
        QVERIFY(lctest::openBuiltinWith(*w_, "atrium", {{"width", "480"}, {"height", "270"}}));
    }
    void cleanup() { w_.reset(); }

    void proxySettingsMissesAndExplain() {
        auto* algorithm = w_->findChild<QComboBox*>("param_algorithm");
        auto* level = w_->findChild<QSpinBox*>("param_proxy-level");
        auto* overfit = w_->findChild<QComboBox*>("param_proxy-overfit");
        auto* conservative = w_->findChild<QCheckBox*>("param_conservative");
        QVERIFY(algorithm && level && overfit && conservative);
        QVERIFY2(!level->isVisible(), "the proxy settings show only for raster");

        // Pick raster in the box, as a person does.
        algorithm->setFocus();
        algorithm->setCurrentIndex(algorithm->findText("raster"));
        emit algorithm->textActivated("raster");
        QVERIFY(doc()->runs().settings().algorithm == lc::Algorithm::Raster);
        QTRY_VERIFY(level->isVisible() && overfit->isVisible() && conservative->isVisible());
        QVERIFY(conservative->isChecked());
        QCOMPARE(overfit->currentText(), QString("auto"));
        for (const char* bar : {"cullToolbar", "limitsToolbar"})
            if (auto* b = w_->findChild<QToolBar*>(bar)) QVERIFY2(!overflows(b), bar);
        QVERIFY(w_->findChild<QSpinBox*>("param_tile")->isVisible());

        // Level 0 and an overfit of 1, typed: the inscribed icosahedron.
        level->setFocus();
        level->selectAll();
        QTest::keyClicks(level, "0");
        QTest::keyClick(level, Qt::Key_Return);
        QCOMPARE(doc()->runs().settings().proxyLevel, 0u);
        overfit->setFocus();
        overfit->lineEdit()->selectAll();
        QTest::keyClicks(overfit->lineEdit(), "1");
        QTest::keyClick(overfit->lineEdit(), Qt::Key_Return);
        QCOMPARE(doc()->runs().settings().proxyOverfit, 1.0);
        QVERIFY(lctest::waitRun(*w_, w_->runCulling(), true));
        auto run = doc()->runs().runOutput();
        QVERIFY(run && run->result.algorithm == lc::Algorithm::Raster);
        QVERIFY2(run->truth.metrics.falseNegatives > 0, "the inscribed proxy misses lights");
        QVERIFY(!run->result.coverage.empty());

        // Next miss, then Explain: the proxy's coverage is the failed step.
        QAction* next = w_->findChild<QAction*>("actionNextMiss");
        QVERIFY(next);
        next->trigger();
        auto* explain = w_->findChild<ExplainPanel*>();
        QVERIFY(explain);
        QTRY_VERIFY(explain->findChild<QPlainTextEdit*>() &&
                    explain->findChild<QPlainTextEdit*>()->toPlainText().contains("proxy coverage: icosphere level 0"));
        const QString text = explain->findChild<QPlainTextEdit*>()->toPlainText();
        QVERIFY2(text.contains("FAIL  proxy coverage"), qPrintable(text));
        QDir().mkpath(LC_RENDER_OUT_DIR);
        w_->cameraView()->renderNow();
        QVERIFY(w_->grab().save(QString(LC_RENDER_OUT_DIR) + "/raster_studio.png"));

        // Overfit auto: the enclosing factor, no misses.
        overfit->setCurrentIndex(overfit->findText("auto"));
        emit overfit->textActivated("auto");
        QCOMPARE(doc()->runs().settings().proxyOverfit, 0.0);
        QVERIFY(lctest::waitRun(*w_, w_->runCulling(), true));
        QCOMPARE(doc()->runs().runOutput()->truth.metrics.falseNegatives, 0u);

        // Depth: slices, as Godot's cluster builder: clustered lists (the
        // cells box's slices), no misses, the cell overlay's froxels; Explain
        // names the slice step.
        auto* depthBox = w_->findChild<QComboBox*>("param_proxy-depth");
        QVERIFY(depthBox && depthBox->isVisible());
        QCOMPARE(depthBox->currentText(), QString("tile"));
        depthBox->setCurrentIndex(depthBox->findText("slices"));
        emit depthBox->textActivated("slices");
        QVERIFY(doc()->runs().settings().proxySlices);
        for (const char* bar : {"cullToolbar", "limitsToolbar", "rasterToolbar"})
            if (auto* b = w_->findChild<QToolBar*>(bar)) QVERIFY2(!overflows(b), bar);
        QVERIFY(lctest::waitRun(*w_, w_->runCulling(), true));
        run = doc()->runs().runOutput();
        QCOMPARE(run->result.listsPerTile, doc()->runs().settings().cells);
        QCOMPARE(run->truth.metrics.falseNegatives, 0u);
        // The inscribed proxy again, with slices: a miss, explained down to the slices.
        overfit->lineEdit()->selectAll();
        QTest::keyClicks(overfit->lineEdit(), "1");
        QTest::keyClick(overfit->lineEdit(), Qt::Key_Return);
        QVERIFY(lctest::waitRun(*w_, w_->runCulling(), true));
        QVERIFY(doc()->runs().runOutput()->truth.metrics.falseNegatives > 0);
        next->trigger();
        QTRY_VERIFY(explain->findChild<QPlainTextEdit*>()->toPlainText().contains("proxy coverage"));
        const QString sliced = explain->findChild<QPlainTextEdit*>()->toPlainText();
        QVERIFY2(sliced.contains("MISSING"), qPrintable(sliced));
        w_->cameraView()->renderNow();
        QVERIFY(w_->grab().save(QString(LC_RENDER_OUT_DIR) + "/raster_slices_studio.png"));
        overfit->setCurrentIndex(overfit->findText("auto"));
        emit overfit->textActivated("auto");
        // A bad number is refused by name; the setting stays.
        overfit->lineEdit()->selectAll();
        QTest::keyClicks(overfit->lineEdit(), "9");
        QTest::keyClick(overfit->lineEdit(), Qt::Key_Return);
        QCOMPARE(doc()->runs().settings().proxyOverfit, 0.0);

        // Another algorithm hides the proxy settings again.
        algorithm->setCurrentIndex(algorithm->findText("minmax"));
        emit algorithm->textActivated("minmax");
        QTRY_VERIFY(!level->isVisible());
    }
};

LC_STUDIO_TEST_MAIN(RasterStudioTest)
#include "test_raster_studio.moc"
