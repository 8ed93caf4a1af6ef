// Culling > Hunt for a miss... as a user works with it: the dialog (filled in
// through its widgets and its Hunt button) refuses a folder holding other
// files and keeps the values typed; a hunt of the flawed tile-edge shader
// shows its progress in the status bar, asks before replacing the edited
// scene, opens the shrunk repro with the verdict's miss selected and Explain
// showing it; a built-in algorithm's hunt with no miss leaves the scene
// alone; Cancel stops a hunt without a limit and keeps what it covered.

#include "studio_test_support.hpp"

#include "document/document.hpp"
#include "panels/explain_panel.hpp"
#include "window/main_window.hpp"
#include "panels/hunt_dialog.hpp"
#include "document/miss_navigator.hpp"

#include "culling/custom/custom_cull.hpp"
#include "culling/scene/scene_io.hpp"

#include <QAction>
#include <QCheckBox>
#include <QDialog>
#include <QDialogButtonBox>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QFile>
#include <QLabel>
#include <QLineEdit>
#include <QPlainTextEdit>
#include <QProcess>
#include <QPushButton>
#include <QRadioButton>
#include <QSpinBox>
#include <QTimer>
#include <QToolButton>
#include <QUndoStack>
#include <QWindow>

#include <fstream>
#include <functional>
#include <sstream>

using namespace lcui;

namespace {

const QString kExamples = QStringLiteral(LC_SOURCE_DIR) + "/resources/culling-examples/";

std::string readAll(const QString& path) {
    std::ifstream in(path.toStdString());
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

QDialog* openHuntDialog() {
    for (QWidget* w : QApplication::topLevelWidgets())
        if (auto* d = qobject_cast<QDialog*>(w); d && d->isVisible() && d->findChild<QSpinBox*>("huntTrials"))
            return d;
    return nullptr;
}

} // namespace

class HuntStudioTest : public QObject {
    Q_OBJECT
    std::unique_ptr<MainWindow> w_;
    QTemporaryDir tmp_;
    Document* doc() const { return w_->document(); }

    // Triggers Culling > Hunt for a miss... and, once the dialog shows, lets
    // `fill` set its widgets and press Hunt (or not: `fill` returns false to
    // leave it open for a second look). Returns when the hunt is over.
    void huntThroughDialog(const std::function<void(QDialog*)>& fill) {
        bool filled = false;
        QTimer poll;
        connect(&poll, &QTimer::timeout, [&] {
            QDialog* d = openHuntDialog();
            if (!d || filled) return;
            filled = true;
            fill(d);
        });
        poll.start(20);
        w_->action("actionHunt")->trigger();
        poll.stop();
        QVERIFY(filled);
    }
    static void press(QDialog* d, QDialogButtonBox::StandardButton b) {
        QTest::mouseClick(d->findChild<QDialogButtonBox*>()->button(b), Qt::LeftButton);
    }
    static void setText(QDialog* d, const char* name, const QString& text) {
        auto* e = d->findChild<QLineEdit*>(name);
        e->selectAll();
        QTest::keyClicks(e, text);
    }

private slots:
    void init() {
        w_ = lctest::makeTestWindow();
        QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
        QVERIFY(w_->openBuiltin("atrium"));
        doc()->undoStack()->clear();
    }
    void cleanup() {
        doc()->undoStack()->setClean();
        w_.reset();
    }

    void flawedShaderIsHuntedAndItsReproOpensAtTheMiss() {
        const QString mine = tmp_.path() + "/mine.comp";
        std::ofstream(mine.toStdString()) << readAll(kExamples + "flawed_tile_edges.comp");
        QVERIFY(w_->setCustomShader(mine));
        // An edit not saved: the repro must not replace it unasked.
        doc()->moveLight(0, doc()->scene().lights[0].position + glm::dvec3(0.5, 0, 0), 1);
        QVERIFY(doc()->isDirty());
        int asked = 0;
        w_->prompts.askUnsaved = [&](QWidget*, const QString&) {
            ++asked;
            return QMessageBox::Discard;
        };
        const QString folder = tmp_.path() + "/hunt";
        QDir().mkpath(folder);
        std::ofstream((folder + "/notes.txt").toStdString()) << "mine\n";
        // (This hunt finds its miss within a second, before the status row's
        // first trial count: cancelStopsAHuntWithoutLimits checks that count.)
        bool refused = false;
        huntThroughDialog([&](QDialog* d) {
            QVERIFY(d->findChild<QLabel*>("huntUnderTest")->text().contains("mine.comp"));
            QDir().mkpath(LC_RENDER_OUT_DIR);
            d->grab().save(QStringLiteral(LC_RENDER_OUT_DIR "/hunt_dialog.png")); // to look at
            QVERIFY(d->findChild<QCheckBox*>("huntOverflow")->isEnabled()); // a custom shader has a capacity
            d->findChild<QSpinBox*>("huntTrials")->setValue(60);
            d->findChild<QDoubleSpinBox*>("huntSeconds")->setValue(0);
            d->findChild<QSpinBox*>("huntSeed")->setValue(1);
            QTest::mouseClick(d->findChild<QRadioButton*>("huntGenerated"), Qt::LeftButton);
            setText(d, "huntFolder", folder);
            press(d, QDialogButtonBox::Ok);
            // notes.txt is not an earlier hunt's: refused, the dialog open.
            const QString why = d->findChild<QLabel*>("huntError")->text();
            refused = d->isVisible() && why.contains("notes.txt");
            QVERIFY2(refused, qPrintable(why));
            QCOMPARE(d->findChild<QSpinBox*>("huntTrials")->value(), 60);
            QFile::remove(folder + "/notes.txt");
            press(d, QDialogButtonBox::Ok);
        });
        QVERIFY(refused);
        QCOMPARE(asked, 1);
        const QString log = w_->messageLog()->toPlainText();
        QVERIFY2(log.contains("COUNTEREXAMPLE"), qPrintable(log));
        for (const char* f : {"scene.json", "repro.sh", "summary.json", "verdict.txt", "run/summary.json"})
            QVERIFY2(QFile::exists(folder + "/" + f), f);
        // The repro is the scene, and the same as the CLI's for seed 1.
        QCOMPARE(doc()->filePath(), folder + "/scene.json");
        QVERIFY(doc()->scene().lights.size() <= 5);
        QVERIFY(!doc()->isDirty());
        QCOMPARE(w_->customShaderPath(), mine);
        // Its run selects the first miss and shows Explain.
        QTRY_VERIFY_WITH_TIMEOUT(w_->missNavigator()->current() == 0, lctest::kRunTimeoutMs);
        const auto run = doc()->runs().runOutput();
        QVERIFY(run && run->truthComputed && run->truth.metrics.falseNegatives > 0);
        const auto missed = lc::locateFalseNegatives(*run, lc::Projection(doc()->scene().camera));
        QCOMPARE(doc()->selection().selectedTile(), int(missed.front().tile));
        QCOMPARE(doc()->selection().selectedLights(), std::vector<int>{int(missed.front().light)});
        QCOMPARE(doc()->selection().explainedList(), int(missed.front().list));
        QVERIFY(w_->findChild<QDockWidget*>("explainDock")->isVisible());
        w_->grabWindow().save(QStringLiteral(LC_RENDER_OUT_DIR "/hunt_repro_open.png")); // to look at
        // verdict.txt names the same light and tile.
        const std::string verdict = readAll(folder + "/verdict.txt");
        QVERIFY2(verdict.find("Light " + std::to_string(missed.front().light) + " ") != std::string::npos,
                 verdict.c_str());
    }

    // The CLI's repro folder opens in the studio the same way: studio.sh
    // starts it on scene.json with the hunted culling, and its first miss is
    // the one the hunt's verdict names.
    void cliReproOpensInTheStudioAtItsMiss() {
        const QString folder = tmp_.path() + "/cli";
        QProcess hunt;
        hunt.start(LC_CLI_PATH, {"hunt", "--shader", kExamples + "flawed_tile_edges.comp", "--backend", "cpu",
                                 "--trials", "60", "--seed", "1", "--out", folder});
        QVERIFY(hunt.waitForFinished(lctest::kRunTimeoutMs));
        QCOMPARE(hunt.exitCode(), 3);
        QProcess studio;
        QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
        env.insert("LIGHTCULL_STUDIO", LC_STUDIO_PATH);
        studio.setProcessEnvironment(env);
        studio.start("sh", {folder + "/studio.sh", "--screenshot", tmp_.path() + "/cli.png", "--quit"});
        QVERIFY(studio.waitForFinished(lctest::kRunTimeoutMs));
        const QString out = QString::fromUtf8(studio.readAllStandardOutput());
        QVERIFY2(studio.exitCode() == 0, qPrintable(out + studio.readAllStandardError()));
        const std::string verdict = readAll(folder + "/verdict.txt");
        const auto light = verdict.find("Light ");
        QVERIFY(light != std::string::npos);
        const std::string lightId = verdict.substr(light + 6, verdict.find(' ', light + 6) - light - 6);
        const auto tile = verdict.find("list of tile ");
        const std::string tileId = verdict.substr(tile + 13, verdict.find(' ', tile + 13) - tile - 13);
        QVERIFY2(out.contains(QString::fromStdString("miss 1 of ")) &&
                     out.contains(QString::fromStdString(": light " + lightId + " ")) &&
                     out.contains(QString::fromStdString("in tile " + tileId + " ")),
                 qPrintable(out + "\nverdict: " + QString::fromStdString(verdict)));
    }

    void builtinWithoutAMissLeavesTheSceneAlone() {
        const std::string before = lc::serializeScene(doc()->scene());
        const QString folder = tmp_.path() + "/quiet";
        huntThroughDialog([&](QDialog* d) {
            QVERIFY(d->findChild<QLabel*>("huntUnderTest")->text().contains("built-in algorithm 2.5d"));
            QVERIFY(!d->findChild<QCheckBox*>("huntOverflow")->isEnabled());
            auto* openScene = d->findChild<QRadioButton*>("huntOpenScene");
            QVERIFY(openScene->isEnabled()); // atrium has meshes
            QTest::mouseClick(openScene, Qt::LeftButton);
            QVERIFY(openScene->isChecked());
            QVERIFY(!d->findChild<QCheckBox*>("huntVary_scene")->isEnabled()); // its meshes stay
            d->findChild<QSpinBox*>("huntTrials")->setValue(15);
            d->findChild<QDoubleSpinBox*>("huntSeconds")->setValue(0);
            setText(d, "huntFolder", folder);
            press(d, QDialogButtonBox::Ok);
        });
        QCOMPARE(lc::serializeScene(doc()->scene()), before);
        QCOMPARE(doc()->filePath(), QString());
        const std::string verdict = readAll(folder + "/verdict.txt");
        QVERIFY2(verdict.rfind("no miss in 15 trials of seed", 0) == 0, verdict.c_str());
        QVERIFY(!QFile::exists(folder + "/scene.json"));
        QVERIFY(w_->messageLog()->toPlainText().contains("no miss in 15 trials"));
    }

    void cancelStopsAHuntWithoutLimits() {
        const QString folder = tmp_.path() + "/cancelled";
        bool cancelled = false;
        QTimer poll;
        connect(&poll, &QTimer::timeout, [&] {
            auto* cancel = w_->findChild<QToolButton*>("statusCancel_load");
            auto* label = w_->findChild<QLabel*>("statusTask_load");
            // Pressed once the hunt has reported some trials.
            if (!cancel || !cancel->isVisible() || cancelled || !label || !label->text().contains("trials")) return;
            // Through the window, as the window system delivers a real click
            // (a click sent to the button itself skips the window's filter).
            QWindow* window = w_->windowHandle();
            const QPoint at = cancel->mapTo(w_.get(), cancel->rect().center());
            QTest::mouseClick(window, Qt::LeftButton, Qt::NoModifier, at);
            cancelled = true;
        });
        poll.start(20);
        lcui::HuntRequest r;
        r.trials = 0;
        r.seconds = 0;
        r.folder = folder;
        // Not through the dialog: it refuses a hunt without limits, rightly.
        huntThroughDialog([&](QDialog* d) {
            d->findChild<QSpinBox*>("huntTrials")->setValue(0);
            d->findChild<QDoubleSpinBox*>("huntSeconds")->setValue(0);
            setText(d, "huntFolder", folder);
            press(d, QDialogButtonBox::Ok);
            QVERIFY(d->findChild<QLabel*>("huntError")->text().contains("trial count or a time budget"));
            press(d, QDialogButtonBox::Cancel);
        });
        r.seconds = 3600;
        QVERIFY(!w_->hunt(r));
        poll.stop();
        QVERIFY(cancelled);
        const std::string verdict = readAll(folder + "/verdict.txt");
        QVERIFY2(verdict.rfind("cancelled: no miss in ", 0) == 0, verdict.c_str());
        QTRY_VERIFY(!w_->findChild<QToolButton*>("statusCancel_load"));
    }
};

int main(int argc, char** argv) {
    return lctest::runQtTest([]() -> QObject* { return new HuntStudioTest; }, argc, argv);
}

#include "test_hunt_studio.moc"
