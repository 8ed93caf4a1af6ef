// The Report dock under Xvfb, driven like a user: the parameter menus hold
// parameters (as the CLI's flags do) and the dock counts what they queue;
// Run (button) sweeps the document's scene on its own thread, estimating the
// time first and asking before a long sweep; the progress bar counts
// configurations and the status says the time left; Cancel keeps the rows
// that finished as a partial report; hovering a point names its
// configuration, and clicking it loads that configuration into the document
// and culls it, so the views show its result.
#include "studio_test_support.hpp"

#include "document/document.hpp"
#include "window/main_window.hpp"
#include "panels/report_dock.hpp"

#include "culling/core/backend.hpp"
#include "culling/core/pipeline.hpp"

#include <QComboBox>
#include <QDockWidget>
#include <QLabel>
#include <QMenu>
#include <QMouseEvent>
#include <QProgressBar>
#include <QPushButton>
#include <QRegularExpression>
#include <QSpinBox>
#include <QToolButton>
#include <QUndoStack>

#include <vtkRenderWindow.h>

#include <set>

using namespace lcui;

namespace {
constexpr int kTimeoutMs = 120000; // 2 shared cores
}

class ReportDockTest : public QObject {
    Q_OBJECT

    std::unique_ptr<MainWindow> w_;
    ReportDock* dock_ = nullptr;
    QStringList prompts_; // what the dock asked (confirm)

    Document* doc() { return w_->document(); }
    QString statusText() { return dock_->findChild<QLabel*>("reportStatus")->text(); }
    QString queueText() { return dock_->findChild<QLabel*>("reportQueue")->text(); }

    // Ticks exactly `values` in parameter `name`'s menu, as a user would
    // (the wanted ones first: the last ticked value cannot be unticked).
    bool hold(const QString& name, const QStringList& values) {
        auto* button = dock_->findChild<QToolButton*>("reportParam_" + name);
        if (!button || !button->menu()) return false;
        const QList<QAction*> actions = button->menu()->actions();
        for (QAction* a : actions)
            if (a->isCheckable() && values.contains(a->data().toString()) && !a->isChecked()) a->trigger();
        for (QAction* a : actions)
            if (a->isCheckable() && !values.contains(a->data().toString()) && a->isChecked()) a->trigger();
        QStringList on;
        for (QAction* a : actions)
            if (a->isCheckable() && a->isChecked()) on << a->data().toString();
        return on.size() == values.size();
    }
    bool sweepEvery(const QString& name) {
        auto* button = dock_->findChild<QToolButton*>("reportParam_" + name);
        if (!button || !button->menu()) return false;
        button->menu()->findChild<QAction*>("every")->trigger();
        return true;
    }

    // CPU backend, one timed run per configuration, no warm-up.
    void chooseCpu() {
        auto* backend = dock_->findChild<QComboBox*>("reportBackend");
        backend->setCurrentIndex(backend->findData("cpu"));
        dock_->findChild<QSpinBox*>("reportRepeat")->setValue(1);
        dock_->options().warmup = 0;
    }

    bool runToEnd() {
        QSignalSpy done(dock_, &ReportDock::finished);
        QTest::mouseClick(dock_->findChild<QPushButton*>("reportRun"), Qt::LeftButton);
        return done.wait(kTimeoutMs) && done.first().at(0).toBool();
    }

    // A row of the report unlike the document's settings (tile 16, cells 32,
    // planes): tile 8, 4 cells, the exact test.
    std::size_t rowUnlikeTheDocument() {
        const lc::Report* rep = dock_->report();
        for (std::size_t i = 0; i < rep->rows.size(); ++i) {
            const lc::ReportConfig& c = rep->rows[i].config;
            if (c.tileSize == 8 && c.settings.cells == 4 && c.settings.test == lc::SphereTest::Exact) return i;
        }
        return rep->rows.size();
    }

    // Runs 2.5d at tiles 8 and 32, 4 and 32 cells, and renders the chart.
    void runSmall25d() {
        chooseCpu();
        QVERIFY(hold("algorithm", {"2.5d"}));
        QVERIFY(hold("tile", {"8", "32"}));
        QVERIFY(hold("cells", {"4", "32"}));
        QVERIFY(runToEnd());
        dock_->chartWidget()->renderWindow()->Render();
        QTest::qWait(100);
    }

private slots:
    void init() {
        w_ = lctest::makeTestWindow(QSize(1400, 900));
        QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
        QVERIFY(w_->openBuiltin("atrium"));
        QVERIFY(w_->setParamFromUi("width", "96"));
        QVERIFY(w_->setParamFromUi("height", "64"));
        QVERIFY(w_->setParamFromUi("tile", "16"));
        doc()->undoStack()->clear();
        dock_ = w_->findChild<ReportDock*>();
        QVERIFY(dock_);
        prompts_.clear();
        // No test sweep is long: a question is unexpected unless a test asks for one.
        dock_->confirm = [this](QWidget*, const QString&, const QString& text) {
            prompts_ << text;
            return true;
        };
        dock_->confirmAboveSeconds = 1e9;
        // Tabbed behind the log by default: float it at a readable size.
        // (inside a scroll area inside the dock)
        QDockWidget* frame = nullptr;
        for (QWidget* p = dock_->parentWidget(); p && !frame; p = p->parentWidget()) frame = qobject_cast<QDockWidget*>(p);
        QVERIFY(frame);
        frame->setFloating(true);
        frame->resize(1100, 520);
        frame->show();
        frame->raise();
        QVERIFY(QTest::qWaitForWindowExposed(frame));
    }

    void cleanup() {
        if (w_) doc()->undoStack()->setClean();
        dock_ = nullptr;
        w_.reset();
    }

    // The queue label follows every scene edit, and a Live drag makes one per
    // step: it must neither look for devices again (each look opens a Vulkan
    // instance, tens of ms on lavapipe: the studio's drag ran at 7 Hz with
    // it) nor miss what the count does depend on (spot lights add rows).
    void lightEditsDoNotLookForDevicesAgain() {
        QVERIFY(!doc()->scene().lights.empty());
        QVERIFY(!doc()->scene().hasSpotLights());
        const int drag = doc()->newDragId();
        doc()->moveLight(0, doc()->scene().lights[0].position + glm::dvec3(0.05, 0, 0), drag);
        const std::size_t before = dock_->queuedConfigurations();
        const QString label = queueText();
        const std::uint64_t opened = lc::vulkanInstancesOpened();
        for (int i = 1; i <= 20; ++i)
            doc()->moveLight(0, doc()->scene().lights[0].position + glm::dvec3(0.05, 0, 0), drag);
        QCOMPARE(lc::vulkanInstancesOpened(), opened);
        QCOMPARE(queueText(), label);
        lc::PointLight spot = doc()->scene().lights[0];
        spot.kind = lc::LightKind::Spot;
        doc()->setLight(0, spot);
        QVERIFY(doc()->scene().hasSpotLights());
        QVERIFY2(dock_->queuedConfigurations() > before, qPrintable(queueText()));
        QVERIFY(queueText() != label);
        QCOMPARE(lc::vulkanInstancesOpened(), opened);
    }

    void runFillsTheReportAndTheProgressBar() {
        chooseCpu();
        QVERIFY(hold("algorithm", {"halfz"}));
        QVERIFY(hold("tile", {"8", "16"}));
        QCOMPARE(dock_->queuedConfigurations(), std::size_t(6)); // 2 tiles x 3 sphere tests
        QVERIFY2(queueText().startsWith("Queues 6 configurations"), qPrintable(queueText()));
        QVERIFY(runToEnd());
        const lc::Report* rep = dock_->report();
        QVERIFY(rep);
        QCOMPARE(rep->rows.size(), std::size_t(6));
        QCOMPARE(rep->width, 96u);
        for (const lc::ReportRow& r : rep->rows) {
            QVERIFY(r.config.backend == "cpu");
            QVERIFY(r.config.settings.algorithm == lc::Algorithm::HalfZ);
            QVERIFY(r.falseNegatives == 0);
        }
        QCOMPARE(dock_->progressBar()->value(), dock_->progressBar()->maximum());
        QCOMPARE(dock_->progressBar()->maximum(), 6);
        QCOMPARE(dock_->progressBar()->text(), QString("6 of 6"));
        QVERIFY(prompts_.isEmpty());
    }

    // Each swept parameter can be held at one value or a subset, through the
    // same ReportOptions the CLI's flags fill; the dock counts the queue.
    void holdingParametersNarrowsTheSweep() {
        chooseCpu();
        const auto& lights = doc()->scene().lights;
        const bool spots = std::any_of(lights.begin(), lights.end(), [](const lc::PointLight& l) { return l.isSpot(); });
        // The default: the default sweep, as `lightcull report --backend cpu`.
        const std::size_t all = lc::reportConfigs(lc::ReportOptions{}, "cpu", spots).size();
        QCOMPARE(dock_->queuedConfigurations(), all);
        QVERIFY2(queueText().contains(QLocale(QLocale::English).toString(qulonglong(all)) + " configurations"),
                 qPrintable(queueText()));
        for (const char* p : {"algorithm", "test", "tile", "cells", "slicing", "skip-empty"})
            QVERIFY2(dock_->findChild<QToolButton*>(QString("reportParam_") + p), p);
        QVERIFY(dock_->findChild<QToolButton*>("reportParam_spot-test"));

        QVERIFY(hold("algorithm", {"minmax", "2.5d"}));
        QVERIFY(hold("test", {"exact"}));
        QVERIFY(hold("tile", {"16"}));
        QVERIFY(hold("cells", {"4"}));
        QVERIFY(hold("spot-test", {"apex-sphere"}));
        // ReportOptions::fixed {algorithm: "minmax,2.5d", test: exact, spot-test:
        // apex-sphere}, tileSizes {16}, cellCounts {4}: minmax once, 2.5d once
        // per slicing.
        QCOMPARE(dock_->queuedConfigurations(), std::size_t(3));
        QVERIFY2(queueText().startsWith("Queues 3 configurations"), qPrintable(queueText()));
        QVERIFY(dock_->findChild<QToolButton*>("reportParam_algorithm")->text().contains("minmax,2.5d"));
        QVERIFY(runToEnd());
        const lc::Report* rep = dock_->report();
        QCOMPARE(rep->rows.size(), std::size_t(3));
        std::set<std::string> labels;
        for (const lc::ReportRow& r : rep->rows) {
            QVERIFY(r.config.settings.algorithm == lc::Algorithm::MinMax ||
                    r.config.settings.algorithm == lc::Algorithm::TwoPointFiveD);
            QVERIFY(r.config.settings.test == lc::SphereTest::Exact);
            QCOMPARE(r.config.tileSize, 16u);
            if (r.config.settings.algorithm == lc::Algorithm::TwoPointFiveD) QCOMPARE(r.config.settings.cells, 4u);
            labels.insert(r.config.label());
        }
        QCOMPARE(labels.size(), std::size_t(3));
        // "Every value" sweeps a parameter again.
        QVERIFY(sweepEvery("test"));
        QCOMPARE(dock_->queuedConfigurations(), std::size_t(9));
    }

    // Before a run: the count and, once a run of this scene has set the pace,
    // an estimate; without one, the first configuration is the timing. Either
    // way a sweep over the limit is asked about, and No keeps what finished.
    void estimateAndConfirmBeforeALongSweep() {
        chooseCpu();
        QVERIFY(hold("algorithm", {"minmax"}));
        QVERIFY(hold("tile", {"8", "16", "32"}));
        const std::size_t n = dock_->queuedConfigurations();
        QVERIFY(n >= 3);
        QVERIFY2(queueText().contains("not known yet"), qPrintable(queueText()));
        QVERIFY(!dock_->estimatedSeconds());

        // No pace yet: the sweep times its first configuration, then asks.
        dock_->confirmAboveSeconds = 0;
        dock_->confirm = [this](QWidget*, const QString&, const QString& text) {
            prompts_ << text;
            return false;
        };
        QSignalSpy started(dock_, &ReportDock::started);
        QVERIFY(!runToEnd());
        QCOMPARE(prompts_.size(), 1);
        QVERIFY2(prompts_[0].contains(QString("%1 configurations").arg(n)) && prompts_[0].contains("first configuration"),
                 qPrintable(prompts_[0]));
        const lc::Report* rep = dock_->report();
        QVERIFY(rep);
        QVERIFY(rep->cancelled);
        QCOMPARE(rep->rows.size(), std::size_t(1));
        QCOMPARE(rep->queued, n);
        QVERIFY2(statusText().contains(QString("cancelled after 1 of %1").arg(n)), qPrintable(statusText()));

        // That run set the pace: the estimate is shown, and asked about before starting.
        QVERIFY(dock_->estimatedSeconds().has_value());
        QVERIFY(*dock_->estimatedSeconds() > 0);
        QVERIFY2(queueText().contains("estimate from the last run"), qPrintable(queueText()));
        QTest::mouseClick(dock_->findChild<QPushButton*>("reportRun"), Qt::LeftButton);
        QCOMPARE(prompts_.size(), 2);
        QVERIFY2(prompts_[1].contains(QString("%1 configurations").arg(n)) && prompts_[1].contains("estimate"),
                 qPrintable(prompts_[1]));
        QCOMPARE(started.size(), 1); // declined: nothing started
        QVERIFY(!dock_->isRunning());
        QCOMPARE(dock_->report()->rows.size(), std::size_t(1));

        // Under the limit: no question, the whole sweep.
        dock_->confirmAboveSeconds = 1e9;
        QVERIFY(runToEnd());
        QCOMPARE(prompts_.size(), 2);
        QCOMPARE(dock_->report()->rows.size(), n);
        QVERIFY(!dock_->report()->cancelled);
    }

    // While running: the bar counts configurations from the first, the
    // status says the time left. Cancel keeps the finished rows, plotted and
    // summarised as a partial report.
    void progressAndCancelKeepTheFinishedRows() {
        chooseCpu();
        // Every algorithm, 9 tile sizes: hundreds of configurations.
        QVERIFY(hold("tile", {"4", "8", "12", "16", "20", "24", "32", "48", "64"}));
        QSignalSpy done(dock_, &ReportDock::finished);
        QTest::mouseClick(dock_->findChild<QPushButton*>("reportRun"), Qt::LeftButton);
        QVERIFY(dock_->isRunning());
        QTRY_VERIFY_WITH_TIMEOUT(dock_->progressBar()->value() >= 3, kTimeoutMs);
        const int total = dock_->progressBar()->maximum();
        QVERIFY(total > 500);
        QVERIFY2(dock_->progressBar()->text().endsWith(QString(" of %1").arg(total)),
                 qPrintable(dock_->progressBar()->text()));
        QVERIFY2(statusText().contains(QRegularExpression("(about \\d+ (s|min)|under a second) left")),
                 qPrintable(statusText()));
        // The status bar mirrors the sweep; its Cancel stops it as the dock's does.
        auto* statusBar = w_->findChild<QProgressBar*>("statusProgress_report");
        QVERIFY(statusBar && statusBar->isVisible());
        QTRY_VERIFY(statusBar->value() > 0 && statusBar->value() < statusBar->maximum());
        QVERIFY(w_->findChild<QLabel*>("statusTask_report")->text().contains(QString("/%1").arg(total)));
        QTest::mouseClick(w_->findChild<QToolButton*>("statusCancel_report"), Qt::LeftButton);
        QVERIFY(done.wait(kTimeoutMs));
        QCOMPARE(done.first().at(0).toBool(), false);
        QVERIFY(!dock_->isRunning());
        const int k = dock_->progressBar()->value();
        QVERIFY(k >= 3 && k < total);
        const lc::Report* rep = dock_->report();
        QVERIFY(rep && rep->cancelled);
        QCOMPARE(rep->rows.size(), std::size_t(k));
        QCOMPARE(rep->queued, std::size_t(total));
        const QString partial = QString("cancelled after %1 of %2").arg(k).arg(total);
        QVERIFY2(statusText().contains(partial), qPrintable(statusText()));
        QVERIFY2(statusText().contains("Fastest without false negatives"), qPrintable(statusText()));
        QVERIFY2(dock_->chartTitle().contains(partial), qPrintable(dock_->chartTitle()));
        dock_->chartWidget()->renderWindow()->Render();
        QVERIFY(dock_->chartPositionOf(0).has_value());
        QVERIFY(dock_->findChild<QPushButton*>("reportRun")->isEnabled());
        QTRY_VERIFY(!w_->findChild<QProgressBar*>("statusProgress_report"));
        QVERIFY(prompts_.isEmpty());
    }

    // The sweep is a job of the culling worker (one device): culling asked
    // for while it runs is served between its configurations, not after it;
    // and closing the window mid-sweep stops it (no hang at exit).
    void cullingRunsWhileASweepDoes() {
        chooseCpu();
        QVERIFY(hold("tile", {"4", "8", "12", "16", "20", "24", "32", "48", "64"}));
        QTest::mouseClick(dock_->findChild<QPushButton*>("reportRun"), Qt::LeftButton);
        QVERIFY(dock_->isRunning());
        QTRY_VERIFY_WITH_TIMEOUT(dock_->progressBar()->value() >= 1, kTimeoutMs);
        QVERIFY(dock_->progressBar()->maximum() > 500);
        QVERIFY(lctest::waitRun(*w_, w_->runCulling(), true));
        QVERIFY2(dock_->isRunning() && dock_->progressBar()->value() < dock_->progressBar()->maximum(),
                 "the run waited for the whole sweep");
        // Live edits too, one after another, during the sweep.
        w_->setLive(true);
        for (int i = 0; i < 3; ++i) {
            QSignalSpy shown(w_.get(), &MainWindow::runFinished);
            const lc::PointLight l = doc()->scene().lights[0];
            doc()->moveLight(0, l.position + glm::dvec3(0.01, 0, 0), doc()->newDragId());
            QVERIFY(shown.wait(kTimeoutMs));
        }
        QVERIFY(dock_->isRunning());
        w_->setLive(false);
        doc()->undoStack()->setClean();
        dock_ = nullptr;
        w_.reset(); // cancels the sweep on the worker; returns, or the test times out
    }

    // A loaded row sets what decides its result and keeps the user's own
    // values of what does not (the spot test of a scene without spot lights,
    // zbin's bins under 2.5d): they were not part of the choice.
    void loadingARowKeepsWhatItDoesNotDecide() {
        runSmall25d();
        QVERIFY(std::none_of(doc()->scene().lights.begin(), doc()->scene().lights.end(),
                             [](const lc::PointLight& l) { return l.isSpot(); }));
        QVERIFY(w_->setParamFromUi("spot-test", "cone-sphere"));
        QVERIFY(w_->setParamFromUi("bins", "64"));
        const std::size_t row = rowUnlikeTheDocument() < dock_->report()->rows.size() ? rowUnlikeTheDocument() : 0;
        const lc::ReportConfig cfg = dock_->report()->rows[row].config;
        dock_->loadRow(row);
        const lc::CullSettings& s = doc()->runs().settings();
        QVERIFY(s.spotTest == lc::SpotTest::ConeSphere);
        QCOMPARE(s.bins, 64u);
        QVERIFY(s.algorithm == cfg.settings.algorithm);
        QCOMPARE(s.cells, cfg.settings.cells);
        QVERIFY(s.test == cfg.settings.test);
        QCOMPARE(doc()->scene().camera.tileSize, cfg.tileSize);
    }

    // Hovering a point shows its configuration (algorithm, parameters, tile,
    // backend) beside its numbers.
    void tooltipNamesTheConfiguration() {
        runSmall25d();
        const std::size_t target = rowUnlikeTheDocument();
        QVERIFY(target < dock_->report()->rows.size());
        const std::optional<QPoint> at = dock_->chartPositionOf(target);
        QVERIFY(at.has_value());
        QWidget* chart = dock_->chartWidget();
        QMouseEvent move(QEvent::MouseMove, QPointF(*at), QPointF(chart->mapToGlobal(*at)), Qt::NoButton, Qt::NoButton,
                         Qt::NoModifier);
        QApplication::sendEvent(chart, &move);
        QTRY_VERIFY_WITH_TIMEOUT(dock_->chartTooltipVisible(), 5000);
        const QString tip = dock_->chartTooltip();
        // The point under the cursor (a row drawn within a few pixels may win).
        std::size_t shown = dock_->report()->rows.size();
        for (std::size_t i = 0; i < dock_->report()->rows.size(); ++i)
            if (dock_->tooltipOf(i) == tip) shown = i;
        QVERIFY2(shown < dock_->report()->rows.size(), qPrintable(tip));
        QVERIFY((*dock_->chartPositionOf(shown) - *at).manhattanLength() <= 8);
        const lc::ReportConfig& c = dock_->report()->rows[shown].config;
        for (const QString& part : {QString("2.5d"), QString("tile=%1").arg(c.tileSize),
                                    QString("cells=%1").arg(c.settings.cells),
                                    QString("test=") + lc::toString(c.settings.test), QString("(cpu)"),
                                    QString("total"), QString("efficiency")})
            QVERIFY2(tip.contains(part), qPrintable(part + " not in: " + tip));
    }

    void clickingAPointLoadsAndRunsItsConfiguration() {
        // A run of the document's own settings is on screen first.
        w_->runCulling();
        QTRY_VERIFY_WITH_TIMEOUT(doc()->runs().runOutput() && doc()->runs().runOutput()->truthComputed, kTimeoutMs);
        const auto before = doc()->runs().runOutput();
        QCOMPARE(before->result.grid.tileSize, 16u);

        runSmall25d();
        const lc::Report* rep = dock_->report();
        QCOMPARE(rep->rows.size(), std::size_t(2 * 3 * 2 * 2));
        const std::size_t target = rowUnlikeTheDocument();
        QVERIFY(target < rep->rows.size());
        const std::optional<QPoint> at = dock_->chartPositionOf(target);
        QVERIFY(at.has_value());
        QVERIFY(dock_->chartWidget()->rect().contains(*at));
        const QImage shot = dock_->parentWidget()->grab().toImage();
        QDir().mkpath(LC_RENDER_OUT_DIR);
        QVERIFY(shot.save(QString(LC_RENDER_OUT_DIR) + "/report_dock.png"));

        QSignalSpy loaded(dock_, &ReportDock::configurationLoaded);
        QTest::mouseClick(dock_->chartWidget(), Qt::LeftButton, Qt::NoModifier, *at);
        QTRY_COMPARE_WITH_TIMEOUT(loaded.size(), 1, 5000);
        // The point under the cursor (another row drawn within a few pixels
        // may win a tie): its configuration is now the document's.
        const std::size_t got = std::size_t(loaded.first().at(0).toInt());
        const std::optional<QPoint> gotAt = dock_->chartPositionOf(got);
        QVERIFY(gotAt.has_value());
        QVERIFY((*gotAt - *at).manhattanLength() <= 8);
        const lc::ReportConfig& c = rep->rows[got].config;
        QVERIFY(doc()->runs().settings().algorithm == c.settings.algorithm);
        QVERIFY(doc()->runs().settings().test == c.settings.test);
        QCOMPARE(doc()->runs().settings().cells, c.settings.cells);
        QVERIFY(doc()->runs().settings().slicing == c.settings.slicing);
        QCOMPARE(doc()->scene().camera.tileSize, c.tileSize);
        // ... and it was culled: the run on screen is this configuration's,
        // not the one before the click.
        QTRY_VERIFY_WITH_TIMEOUT(doc()->runs().runOutput() != before && doc()->runs().runOutput()->truthComputed, kTimeoutMs);
        const auto run = doc()->runs().runOutput();
        QCOMPARE(run->result.grid.tileSize, c.tileSize);
        QVERIFY(run->result.settings.algorithm == c.settings.algorithm);
        QVERIFY(run->result.settings.test == c.settings.test);
        QCOMPARE(run->result.settings.cells, c.settings.cells);
        QVERIFY(run->result.settings.slicing == c.settings.slicing);
        QCOMPARE(run->truth.metrics.falseNegatives, rep->rows[got].falseNegatives);
        QTRY_VERIFY2(statusText().startsWith("Showing " + QString::fromStdString(c.label())), qPrintable(statusText()));
        // The tile size is a camera edit: one undo step restores 16.
        if (c.tileSize != 16) {
            doc()->undoStack()->undo();
            QCOMPARE(doc()->scene().camera.tileSize, 16u);
        }
    }

    // A report belongs to the scene it swept: opening another drops it (no
    // click can load its points into the new scene), and a sweep running
    // then shows nothing when it ends.
    void anotherSceneDropsTheReport() {
        chooseCpu();
        QVERIFY(hold("algorithm", {"minmax"}));
        QVERIFY(hold("tile", {"16"}));
        QVERIFY(runToEnd());
        QVERIFY(dock_->report());
        doc()->undoStack()->setClean(); // no prompt to save
        QVERIFY(w_->openBuiltin("forest"));
        QVERIFY(!dock_->report());
        QVERIFY(!dock_->chartPositionOf(0).has_value());
        QVERIFY2(statusText().contains("Another scene"), qPrintable(statusText()));

        QVERIFY(w_->setParamFromUi("width", "96"));
        QVERIFY(w_->setParamFromUi("height", "64"));
        QSignalSpy done(dock_, &ReportDock::finished);
        QVERIFY(dock_->start());
        doc()->undoStack()->setClean();
        QVERIFY(w_->openBuiltin("atrium"));
        QVERIFY(done.wait(kTimeoutMs));
        QCOMPARE(done.first().at(0).toBool(), false);
        QVERIFY(!dock_->report());
        QVERIFY2(statusText().contains("Another scene"), qPrintable(statusText()));
    }
};

LC_STUDIO_TEST_MAIN(ReportDockTest)
#include "test_report_dock.moc"
