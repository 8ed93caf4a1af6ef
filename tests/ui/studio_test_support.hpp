#pragma once
// Shared by the ui and render tests: their own main (the GL surface format
// must be set before QApplication, so QTEST_MAIN cannot be used), isolated
// QSettings, the test window every ui test starts from, opening a built-in
// scene with parameters set through the UI, and waiting for a run.

#include <QAction>
#include <QApplication>
#include <QDir>
#include <QElapsedTimer>
#include <QSignalSpy>
#include <QSurfaceFormat>
#include <QTemporaryDir>
#include <QTest>
#include <QVTKOpenGLNativeWidget.h>

#include "document/document.hpp"
#include "window/main_window.hpp"

#include <cstdio>
#include <cstdlib>
#include <memory>

namespace lctest {

// Tests need a real X server (VTK renders through GLX; Qt's offscreen platform
// does not render VTK reliably). No display is a FAILURE, never a skip.
inline int runQtTest(QObject* (*make)(), int argc, char** argv) {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) {
        std::fprintf(stderr,
                     "FAIL: no X display. The ui/render tests need one; run them under Xvfb:\n"
                     "  xvfb-run -a -s \"-screen 0 1920x1080x24\" ctest -L 'ui|render'\n");
        return 1;
    }
    qputenv("QT_QPA_PLATFORM", "xcb");
    // Settings of the test run go to a throw-away folder, not the user's.
    static QTemporaryDir config;
    qputenv("XDG_CONFIG_HOME", config.path().toUtf8());
    QSurfaceFormat::setDefaultFormat(QVTKOpenGLNativeWidget::defaultFormat());
    QApplication::setAttribute(Qt::AA_ShareOpenGLContexts);
    QApplication app(argc, argv);
    QApplication::setOrganizationName("LightCullTest");
    QApplication::setApplicationName("studio-tests");
    QObject* test = make();
    const int rc = QTest::qExec(test, argc, argv);
    delete test;
    return rc;
}

// A studio window as the ui tests start it: the CPU backend, Live off, no run
// on open (tests shrink the resolution first), any error dialog a test
// failure, shown at `size`. The caller waits for it to be exposed.
inline std::unique_ptr<lcui::MainWindow> makeTestWindow(QSize size = QSize(1400, 850)) {
    auto w = std::make_unique<lcui::MainWindow>();
    w->prompts.showError = [](QWidget*, const QString& t, const QString& m) {
        QFAIL(qPrintable("unexpected error dialog: " + t + ": " + m));
    };
    w->setBackend("cpu");
    w->setLive(false);
    w->runOnOpen = false;
    w->resize(size);
    w->show();
    return w;
}

// How long a test waits for one run: generous, 2 shared cores and lavapipe.
constexpr int kRunTimeoutMs = 120000;

// Waits until the window shows run `generation` or a newer one, with its
// ground truth when `truth`. False on a timeout or when that run failed.
inline bool waitRun(lcui::MainWindow& w, quint64 generation, bool truth = false) {
    QSignalSpy done(&w, &lcui::MainWindow::runFinished);
    QSignalSpy failed(&w, &lcui::MainWindow::runFailed);
    const lcui::Document* doc = w.document();
    auto shown = [&] {
        return doc->runs().runGeneration() >= generation && doc->runs().runOutput() && (!truth || doc->runs().runOutput()->truthComputed);
    };
    QElapsedTimer t;
    t.start();
    while (!shown() && t.elapsed() < kRunTimeoutMs) {
        for (const auto& f : failed)
            if (f.at(0).toULongLong() >= generation) return false;
        done.wait(100);
    }
    return shown();
}

// Exports diagnostics as File > Export diagnostics... does (into `dir`: the
// save prompt answered) and waits until the export ends (a run shown as a
// heat map is shaded first). True when it was written.
inline bool exportAndWait(lcui::MainWindow& w, const QString& dir) {
    QSignalSpy ended(&w, &lcui::MainWindow::diagnosticsExported);
    w.prompts.savePath = [dir](QWidget*, const QString&, const QString&) { return dir; };
    w.action("actionExportDiagnostics")->trigger();
    if (ended.isEmpty() && !ended.wait(kRunTimeoutMs)) return false;
    return ended.at(0).at(0).toString() == dir && ended.at(0).at(1).toBool();
}

// Opens a built-in scene and sets culling parameters through the UI as a user
// would (name, value: "width", "320"; the toolbar's parameter names), then
// clears the undo stack: the set-up is not an edit under test. No run: the
// caller runs (waitRun(w, w.runCulling())) after any further set-up.
inline bool openBuiltinWith(lcui::MainWindow& w, const QString& builtin,
                            std::initializer_list<std::pair<const char*, QString>> params) {
    if (!w.openBuiltin(builtin)) return false;
    for (const auto& [name, value] : params)
        if (!w.setParamFromUi(name, value)) return false;
    w.document()->undoStack()->clear();
    return true;
}

} // namespace lctest

#define LC_STUDIO_TEST_MAIN(TestClass)                                                          \
    int main(int argc, char** argv) {                                                           \
        return lctest::runQtTest([]() -> QObject* { return new TestClass; }, argc, argv);      \
    }
