// The Report dock under Xvfb, driven like a user: Run (button) sweeps the
// document's scene on its own thread with a progress bar, Cancel stops a long
// sweep and keeps the previous report, and a mouse click on a plotted point
// loads that configuration (settings and tile size) into the document.
#include "studio_test_support.hpp"

#include "document.hpp"
#include "main_window.hpp"
#include "report_dock.hpp"

#include <QComboBox>
#include <QDockWidget>
#include <QLabel>
#include <QProgressBar>
#include <QPushButton>
#include <QSpinBox>
#include <QToolButton>
#include <QUndoStack>

#include <vtkRenderWindow.h>

using namespace lcui;

namespace {
constexpr int kTimeoutMs = 120000; // 2 shared cores
}

class ReportDockTest : public QObject {
    Q_OBJECT

    std::unique_ptr<MainWindow> w_;
    ReportDock* dock_ = nullptr;

    Document* doc() { return w_->document(); }

    void chooseCpu(const QString& algorithm) {
        auto* backend = dock_->findChild<QComboBox*>("reportBackend");
        backend->setCurrentIndex(backend->findData("cpu"));
        auto* algo = dock_->findChild<QComboBox*>("reportAlgorithm");
        algo->setCurrentIndex(algorithm.isEmpty() ? 0 : algo->findData(algorithm));
        dock_->findChild<QSpinBox*>("reportRepeat")->setValue(1);
        dock_->options().warmup = 0;
    }

    bool runToEnd() {
        QSignalSpy done(dock_, &ReportDock::finished);
        QTest::mouseClick(dock_->findChild<QPushButton*>("reportRun"), Qt::LeftButton);
        return done.wait(kTimeoutMs) && done.first().at(0).toBool();
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
        // Tabbed behind the log by default: float it at a readable size.
        // (inside a scroll area inside the dock)
        QDockWidget* frame = nullptr;
        for (QWidget* p = dock_->parentWidget(); p && !frame; p = p->parentWidget()) frame = qobject_cast<QDockWidget*>(p);
        QVERIFY(frame);
        frame->setFloating(true);
        frame->resize(1000, 460);
        frame->show();
        frame->raise();
        QVERIFY(QTest::qWaitForWindowExposed(frame));
    }

    void cleanup() {
        doc()->undoStack()->setClean();
        dock_ = nullptr;
        w_.reset();
    }

    void runFillsTheReportAndTheProgressBar() {
        chooseCpu("halfz");
        dock_->options().tileSizes = {8, 16};
        QVERIFY(runToEnd());
        const lc::Report* rep = dock_->report();
        QVERIFY(rep);
        QCOMPARE(rep->rows.size(), std::size_t(6)); // 2 tiles x 3 sphere tests
        QCOMPARE(rep->width, 96u);
        for (const lc::ReportRow& r : rep->rows) {
            QVERIFY(r.config.backend == "cpu");
            QVERIFY(r.config.settings.algorithm == lc::Algorithm::HalfZ);
            QVERIFY(r.falseNegatives == 0);
        }
        QCOMPARE(dock_->progressBar()->value(), dock_->progressBar()->maximum());
        QCOMPARE(dock_->progressBar()->maximum(), 6);
    }

    void cancelStopsALongSweepAndKeepsThePreviousReport() {
        chooseCpu("halfz");
        dock_->options().tileSizes = {16};
        QVERIFY(runToEnd());
        QCOMPARE(dock_->report()->rows.size(), std::size_t(3));
        // Every algorithm, 8 tile sizes: hundreds of configurations.
        chooseCpu("");
        dock_->options().tileSizes = {8, 12, 16, 20, 24, 32, 48, 64};
        QSignalSpy done(dock_, &ReportDock::finished);
        QTest::mouseClick(dock_->findChild<QPushButton*>("reportRun"), Qt::LeftButton);
        QVERIFY(dock_->isRunning());
        QTRY_VERIFY_WITH_TIMEOUT(dock_->progressBar()->value() >= 2, kTimeoutMs);
        const int total = dock_->progressBar()->maximum();
        QVERIFY(total > 500);
        // The status bar mirrors the sweep; its Cancel stops it as the dock's does.
        auto* statusBar = w_->findChild<QProgressBar*>("statusProgress_report");
        QVERIFY(statusBar && statusBar->isVisible());
        QTRY_VERIFY(statusBar->value() > 0 && statusBar->value() < statusBar->maximum());
        QVERIFY(w_->findChild<QLabel*>("statusTask_report")->text().contains(QString("/%1").arg(total)));
        QTest::mouseClick(w_->findChild<QToolButton*>("statusCancel_report"), Qt::LeftButton);
        QVERIFY(done.wait(kTimeoutMs));
        QCOMPARE(done.first().at(0).toBool(), false);
        QVERIFY(!dock_->isRunning());
        QVERIFY(dock_->progressBar()->value() < total);
        QCOMPARE(dock_->report()->rows.size(), std::size_t(3)); // the previous report
        QVERIFY(dock_->findChild<QLabel*>("reportStatus")->text().contains("Cancelled"));
        QVERIFY(dock_->findChild<QPushButton*>("reportRun")->isEnabled());
        QTRY_VERIFY(!w_->findChild<QProgressBar*>("statusProgress_report"));
    }

    void clickingAPointLoadsItsConfiguration() {
        chooseCpu("2.5d");
        dock_->options().tileSizes = {8, 32};
        dock_->options().cellCounts = {4, 32};
        QVERIFY(runToEnd());
        const lc::Report* rep = dock_->report();
        QCOMPARE(rep->rows.size(), std::size_t(2 * 3 * 2 * 2));
        dock_->chartWidget()->renderWindow()->Render();
        QTest::qWait(100);
        // A row unlike the document's settings (tile 16, cells 32, planes, log).
        std::size_t target = rep->rows.size();
        for (std::size_t i = 0; i < rep->rows.size() && target == rep->rows.size(); ++i) {
            const lc::ReportConfig& c = rep->rows[i].config;
            if (c.tileSize == 8 && c.settings.cells == 4 && c.settings.test == lc::SphereTest::Exact) target = i;
        }
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
        QVERIFY(doc()->settings().algorithm == c.settings.algorithm);
        QVERIFY(doc()->settings().test == c.settings.test);
        QCOMPARE(doc()->settings().cells, c.settings.cells);
        QVERIFY(doc()->settings().slicing == c.settings.slicing);
        QCOMPARE(doc()->scene().camera.tileSize, c.tileSize);
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
        chooseCpu("minmax");
        dock_->options().tileSizes = {16};
        QVERIFY(runToEnd());
        QVERIFY(dock_->report());
        doc()->undoStack()->setClean(); // no prompt to save
        QVERIFY(w_->openBuiltin("forest"));
        QVERIFY(!dock_->report());
        QVERIFY(!dock_->chartPositionOf(0).has_value());
        auto* status = dock_->findChild<QLabel*>("reportStatus");
        QVERIFY2(status->text().contains("Another scene"), qPrintable(status->text()));

        QVERIFY(w_->setParamFromUi("width", "96"));
        QVERIFY(w_->setParamFromUi("height", "64"));
        QSignalSpy done(dock_, &ReportDock::finished);
        QVERIFY(dock_->start());
        doc()->undoStack()->setClean();
        QVERIFY(w_->openBuiltin("atrium"));
        QVERIFY(done.wait(kTimeoutMs));
        QCOMPARE(done.first().at(0).toBool(), false);
        QVERIFY(!dock_->report());
        QVERIFY2(status->text().contains("Another scene"), qPrintable(status->text()));
    }
};

LC_STUDIO_TEST_MAIN(ReportDockTest)
#include "test_report_dock.moc"
