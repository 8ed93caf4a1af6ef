// lightcull-studio: the Qt + VTK scene editor.
//
//   lightcull-studio [--scene FILE | --builtin NAME] [--lights N [--seed S]] [--run]
//                    [--screenshot FILE.png] [--quit] [--measure-live-drag SECONDS]
//                    [--measure-shading ROUNDS] [--image-mode MODE]
//
// With no arguments it opens the built-in default scene and runs culling once.
// --screenshot grabs the whole main window once the run's result (with its
// shaded pictures, in a shaded --image-mode) has arrived and both views have
// rendered; --quit exits afterwards (exit code 0 only when
// every requested step worked).

#include "views/camera_view.hpp"
#include "work/cull_worker.hpp"
#include "document/document.hpp"
#include "live_drag_probe.hpp"
#include "window/main_window.hpp"
#include "document/miss_navigator.hpp"
#include "shading_probe.hpp"
#include "widgets/count_text.hpp"

#include "culling/core/backend.hpp"
#include "culling/core/params.hpp"
#include "culling/core/presets.hpp"
#include "culling/scene/scene_io.hpp"

#include <QAction>
#include <QApplication>
#include <QCommandLineParser>
#include <QSurfaceFormat>
#include <QTimer>
#include <QVTKOpenGLNativeWidget.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <utility>

namespace {

// VTK renders through GLX only: without an X display, say how to get one
// instead of letting the xcb plugin abort.
bool haveDisplay(int argc, char** argv) {
    const char* platform = std::getenv("QT_QPA_PLATFORM");
    const bool xcb = !platform || std::string(platform).rfind("xcb", 0) == 0;
    if (!xcb) return true; // the user picked another platform on purpose
    const char* display = std::getenv("DISPLAY");
    if (display && *display) return true;
    std::fprintf(stderr,
                 "lightcull-studio: no X display (DISPLAY is not set).\n"
                 "The studio renders with OpenGL through X11. Without a desktop, run it under Xvfb:\n"
                 "  xvfb-run -a -s \"-screen 0 1920x1080x24\" %s",
                 argc > 0 ? argv[0] : "lightcull-studio");
    for (int i = 1; i < argc; ++i) std::fprintf(stderr, " %s", argv[i]);
    std::fprintf(stderr, "\n");
    return false;
}

// A benchmark starts once the opening run's result is in and both views
// have settled.
void startAfterOpeningRun(lcui::MainWindow& window, QObject* probe, std::function<void()> start) {
    const quint64 target = window.cullService()->lastGeneration();
    auto started = std::make_shared<bool>(false);
    QObject::connect(&window, &lcui::MainWindow::runFinished, probe, [probe, target, started, start](quint64 g) {
        if (g >= target && !*started) {
            *started = true;
            QTimer::singleShot(500, probe, start);
        }
    });
}

} // namespace

int main(int argc, char** argv) {
    if (!haveDisplay(argc, argv)) return 2;
    // Must precede QApplication: VTK's widget needs its own GL surface format.
    QSurfaceFormat::setDefaultFormat(QVTKOpenGLNativeWidget::defaultFormat());
    QApplication::setAttribute(Qt::AA_ShareOpenGLContexts);
    QApplication app(argc, argv);
    QApplication::setOrganizationName("LightCull");
    QApplication::setApplicationName("LightCull Studio");

    QCommandLineParser parser;
    parser.setApplicationDescription("LightCull Studio: place lights, run tiled/clustered light culling, "
                                     "see the result.");
    parser.addHelpOption();
    QCommandLineOption sceneOpt("scene", "Open a scene: scene JSON, .gltf or .glb.", "FILE");
    QCommandLineOption builtinOpt("builtin", QString("Open a built-in scene (default %1).").arg(lc::kDefaultBuiltin),
                                  "NAME");
    QCommandLineOption runOpt("run", "Run culling once the scene is open.");
    QCommandLineOption shotOpt("screenshot", "Save a PNG of the window after the run and render.", "FILE.png");
    QCommandLineOption quitOpt("quit", "Quit after the run / screenshot.");
    QCommandLineOption lightsOpt("lights", "Replace the scene's lights with N generated ones (as the CLI's --lights).",
                                 "N");
    QCommandLineOption seedOpt("seed", "Seed of --lights (default 1).", "S", "1");
    QCommandLineOption dragOpt("measure-live-drag",
                               "Benchmark: drag one light with Live on for SECONDS, print the rate of results "
                               "shown and their latency, then quit.",
                               "SECONDS");
    QCommandLineOption shadingOpt("measure-shading",
                                  "Benchmark: in Difference mode, ROUNDS runs alternating a moved light and a "
                                  "switch between 2.5d and clustered; print how long the shaded pictures take "
                                  "after the lists, then quit.",
                                  "ROUNDS");
    QCommandLineOption imageModeOpt("image-mode",
                                    "The camera view's image (as View > Camera image, and remembered like it): "
                                    "heat, shaded-culled, shaded-all or difference.",
                                    "MODE");
    QCommandLineOption shaderOpt("shader",
                                 "Cull with this custom culling shader (as Culling > Custom shader...; "
                                 "docs/CUSTOM_CULLING.md).",
                                 "FILE");
    QCommandLineOption paramOpt("param",
                                "Set a culling parameter as the toolbar does, e.g. algorithm=minmax (repeatable; "
                                "tile, width and height belong to the scene).",
                                "NAME=VALUE");
    QCommandLineOption firstMissOpt("first-miss",
                                    "Once the run has its ground truth, select its first miss and explain it "
                                    "(as Culling > Next miss; a hunt's studio.sh uses it).");
    QCommandLineOption backendOpt("backend", "Culling backend (as the toolbar's; remembered): cpu or vulkan.", "NAME");
    QCommandLineOption presetOpt("preset",
                                 "Cull as an engine does (as the Limits toolbar's Engine preset; docs/ENGINES.md), "
                                 "for the scene once it is open; --param values override it.",
                                 "NAME");
    QCommandLineOption captureOpt("capture",
                                  "Open a renderer's frame from a RenderDoc capture (as File > Open RenderDoc "
                                  "capture...; with --dispatch and --describe, docs/RENDERDOC.md).",
                                  "FILE.rdc");
    QCommandLineOption dispatchOpt("dispatch", "The capture's culling dispatch: its event id or text of its name "
                                               "or markers.", "EVENT|NAME");
    QCommandLineOption describeOpt("describe", "The description of the renderer's lights, camera and lists.",
                                   "FILE.json");
    parser.addOptions({captureOpt, dispatchOpt, describeOpt});
    parser.addOptions({sceneOpt, builtinOpt, lightsOpt, seedOpt, shaderOpt, paramOpt, presetOpt, backendOpt, firstMissOpt, runOpt,
                       shotOpt, quitOpt, dragOpt, shadingOpt, imageModeOpt});
    parser.process(app);
    if (int(parser.isSet(sceneOpt)) + int(parser.isSet(builtinOpt)) + int(parser.isSet(captureOpt)) > 1) {
        std::fprintf(stderr, "lightcull-studio: --scene, --builtin and --capture are exclusive\n");
        return 2;
    }
    if (parser.isSet(captureOpt) != parser.isSet(dispatchOpt) || parser.isSet(captureOpt) != parser.isSet(describeOpt)) {
        std::fprintf(stderr, "lightcull-studio: --capture, --dispatch and --describe go together\n");
        return 2;
    }

    long long lightCount = -1;
    unsigned long long seed = 1;
    double dragSeconds = 0;
    int shadingRounds = 0;
    auto imageMode = lcui::CameraView::ImageMode::Heat;
    {
        bool ok1 = true, ok2 = true, ok3 = true, ok4 = true;
        if (parser.isSet(lightsOpt)) lightCount = parser.value(lightsOpt).toLongLong(&ok1);
        seed = parser.value(seedOpt).toULongLong(&ok2);
        if (parser.isSet(dragOpt)) dragSeconds = parser.value(dragOpt).toDouble(&ok3);
        if (parser.isSet(shadingOpt)) shadingRounds = parser.value(shadingOpt).toInt(&ok4);
        if (!ok1 || lightCount == 0 || lightCount > 1000000 || lightCount < -1) {
            std::fprintf(stderr, "lightcull-studio: --lights: expected a count in [1, 1000000], got '%s'\n",
                         qPrintable(parser.value(lightsOpt)));
            return 2;
        }
        if (!ok2) {
            std::fprintf(stderr, "lightcull-studio: --seed: expected a whole number, got '%s'\n",
                         qPrintable(parser.value(seedOpt)));
            return 2;
        }
        if (!ok3 || (parser.isSet(dragOpt) && !(dragSeconds > 0 && dragSeconds <= 600))) {
            std::fprintf(stderr, "lightcull-studio: --measure-live-drag: expected seconds in (0, 600], got '%s'\n",
                         qPrintable(parser.value(dragOpt)));
            return 2;
        }
        if (!ok4 || (parser.isSet(shadingOpt) && !(shadingRounds >= 2 && shadingRounds <= 1000))) {
            std::fprintf(stderr, "lightcull-studio: --measure-shading: expected rounds in [2, 1000], got '%s'\n",
                         qPrintable(parser.value(shadingOpt)));
            return 2;
        }
        if (parser.isSet(imageModeOpt) && !lcui::CameraView::fromString(parser.value(imageModeOpt), &imageMode)) {
            std::fprintf(stderr,
                         "lightcull-studio: --image-mode: expected heat, shaded-culled, shaded-all or difference, "
                         "got '%s'\n",
                         qPrintable(parser.value(imageModeOpt)));
            return 2;
        }
        if (dragSeconds > 0 && shadingRounds > 0) {
            std::fprintf(stderr, "lightcull-studio: --measure-live-drag and --measure-shading are exclusive\n");
            return 2;
        }
    }

    lcui::MainWindow window;
    // A script has nobody to answer dialogs: errors go to stderr instead.
    const bool scripted = parser.isSet(quitOpt) || dragSeconds > 0 || shadingRounds > 0;
    if (scripted)
        window.prompts.showError = [](QWidget*, const QString& title, const QString& text) {
            std::fprintf(stderr, "lightcull-studio: %s: %s\n", qPrintable(title), qPrintable(text));
        };
    window.show();
    // Before the scene opens, so that its first run brings the pictures.
    if (parser.isSet(imageModeOpt))
        window.action(QString("actionImage_%1").arg(lcui::CameraView::toString(imageMode)))->trigger();

    if (parser.isSet(backendOpt)) {
        const auto names = lc::availableBackends();
        const std::string b = parser.value(backendOpt).toStdString();
        if (std::find(names.begin(), names.end(), b) == names.end()) {
            std::fprintf(stderr, "lightcull-studio: --backend: '%s' is not one of this build's backends\n", b.c_str());
            return 2;
        }
        window.setBackend(parser.value(backendOpt));
    }
    // Culling parameters before the scene opens, so that its run uses them.
    for (const QString& nv : parser.values(paramOpt)) {
        const int eq = nv.indexOf('=');
        const QString name = nv.left(eq), value = nv.mid(eq + 1);
        // The parameter table's own message names the value and what it takes.
        if (eq > 0 && name != "tile" && name != "width" && name != "height") {
            try {
                lc::CullSettings scratch;
                lc::Camera camera;
                lc::setParam(scratch, camera, name.toStdString(), value.toStdString());
            } catch (const std::exception& e) {
                std::fprintf(stderr, "lightcull-studio: --param %s: %s\n", qPrintable(nv), e.what());
                return 2;
            }
        }
        if (eq <= 0 || name == "tile" || name == "width" || name == "height" ||
            !window.setParamFromUi(name, value)) {
            std::fprintf(stderr,
                         "lightcull-studio: --param: '%s' is not NAME=VALUE of a culling parameter (tile, width "
                         "and height belong to the scene)\n",
                         qPrintable(nv));
            return 2;
        }
    }

    if (parser.isSet(presetOpt) && parser.isSet(shaderOpt)) {
        // As the CLI: the shader makes the lists, the preset's culling would not run.
        std::fprintf(stderr, "lightcull-studio: --preset: has no effect with --shader\n");
        return 2;
    }
    if (parser.isSet(presetOpt)) {
        try {
            lc::enginePreset(parser.value(presetOpt).toStdString());
        } catch (const std::exception& e) {
            std::fprintf(stderr, "lightcull-studio: --preset: %s\n", e.what());
            return 2;
        }
    }

    // The scene opens without a run: --lights, --preset and --shader below
    // change what it culls, and the first run is theirs (a custom shader's
    // start would otherwise cull with the built-in algorithm first).
    window.runOnOpen = false;
    bool ok = true;
    if (parser.isSet(captureOpt))
        ok = window.openCapture(parser.value(captureOpt), parser.value(dispatchOpt), parser.value(describeOpt));
    else if (parser.isSet(sceneOpt)) ok = window.openSceneFile(parser.value(sceneOpt));
    else ok = window.openBuiltin(parser.isSet(builtinOpt) ? parser.value(builtinOpt)
                                                          : QString(lc::kDefaultBuiltin));
    if (!ok && scripted) return 1;
    if (ok && lightCount > 0) {
        // Same generator and defaults as the CLI, so both see the same lights.
        lc::Scene scene = window.document()->scene();
        try {
            scene.lights = lc::generateLights(lc::defaultLightGen(scene, std::uint32_t(lightCount), seed));
        } catch (const std::exception& e) {
            std::fprintf(stderr, "lightcull-studio: --lights: %s\n", e.what());
            return 2;
        }
        window.document()->resetScene(std::move(scene), window.document()->filePath());
        window.log(QString("the scene's lights replaced by %1 (--lights, seed %2)")
                       .arg(lcui::countOf(std::uint64_t(lightCount), "generated light", "generated lights"))
                       .arg(seed));
    }
    if (ok && parser.isSet(presetOpt)) {
        // The preset's grid and limits depend on the scene's camera and
        // lights: set once it is open; --param values given beside it win.
        window.setPresetFromUi(parser.value(presetOpt));
        for (const QString& nv : parser.values(paramOpt))
            window.setParamFromUi(nv.left(nv.indexOf('=')), nv.mid(nv.indexOf('=') + 1));
    }
    // (A shader it takes runs culling with it.)
    if (ok && parser.isSet(shaderOpt) && !window.setCustomShader(parser.value(shaderOpt)) && scripted) return 1;
    window.runOnOpen = true;
    const bool wantRun = ok || parser.isSet(runOpt) || parser.isSet(firstMissOpt);
    if (wantRun && window.cullService()->lastGeneration() == 0) window.runCulling();
    if (ok && parser.isSet(firstMissOpt)) {
        window.selectFirstMissOfRun(window.cullService()->lastGeneration());
        if (scripted) // the miss selected, for a script's log
            QObject::connect(window.missNavigator(), &lcui::MissNavigator::message, &app, [](const QString& m) {
                std::fprintf(stdout, "%s\n", qPrintable(m));
            });
    }

    if (dragSeconds > 0) {
        auto* probe = new LiveDragProbe(&window, dragSeconds);
        QObject::connect(probe, &LiveDragProbe::done, &app, [&window, &app](const LiveDragReport& r) {
            std::fprintf(stdout,
                         "live drag: %d edits, %d results shown in %.2f s: %.1f Hz; latency edit->shown "
                         "median %.1f ms, max %.1f ms; per run median depth %.1f ms, cull %.1f ms, "
                         "ground truth %.1f ms (%d completed)\n",
                         r.edits, r.shown, r.seconds, r.rateHz(), r.medianLatencyMs, r.maxLatencyMs,
                         r.medianDepthMs, r.medianCullMs, r.medianTruthMs, r.truths);
            std::fprintf(stdout,
                         "live drag: %zu lights; UI thread per edit median %.1f ms; inspector view %dx%d: "
                         "%d frames, median %.1f ms; camera view: %d frames, median %.1f ms; before the drag "
                         "(median of 3): inspector %.1f ms, camera %.1f ms\n",
                         r.lights, r.medianEditMs, r.inspectorWidth, r.inspectorHeight, r.inspectorFrames,
                         r.medianInspectorMs, r.cameraFrames, r.medianCameraMs, r.staticInspectorMs,
                         r.staticCameraMs);
            std::fprintf(stdout, "live drag: camera view mesh pictures taken: %d\n",
                         window.cameraView()->meshPictureCaptures());
            window.document()->undoStack()->setClean();
            app.exit(r.shown > 0 ? 0 : 1);
        });
        startAfterOpeningRun(window, probe, [probe] { probe->start(); });
        return app.exec();
    }

    if (shadingRounds > 0) {
        auto* probe = new ShadingProbe(&window, shadingRounds);
        QObject::connect(probe, &ShadingProbe::done, &app, [&window, &app](const ShadingReport& r) {
            std::fprintf(stdout,
                         "shading: pictures after the lists, Difference mode: moved light median %.1f ms "
                         "(max %.1f, %d rounds, all-lights image updated each: %s); algorithm switch median "
                         "%.1f ms (max %.1f, %d rounds, all-lights image kept each: %s); culled image "
                         "shading median %.1f ms\n",
                         r.lightMedianMs, r.lightMaxMs, r.lightRounds, r.allLightsUpdatedOnEveryLightRound ? "yes" : "no",
                         r.algorithmMedianMs, r.algorithmMaxMs, r.algorithmRounds,
                         r.allLightsKeptOnEveryAlgorithmRound ? "yes" : "no", r.medianCulledShadeMs);
            window.document()->undoStack()->setClean();
            app.exit(r.lightRounds > 0 && r.algorithmRounds > 0 ? 0 : 1);
        });
        startAfterOpeningRun(window, probe, [probe] { probe->start(); });
        return app.exec();
    }

    const QString shot = parser.value(shotOpt);
    auto finish = [&window, &app, shot, scripted](bool runOk) {
        // Let both views render the result before grabbing.
        QTimer::singleShot(300, &window, [&window, &app, shot, scripted, runOk] {
            int code = runOk ? 0 : 1;
            if (!shot.isEmpty()) {
                const QImage img = window.grabWindow();
                if (img.isNull() || !img.save(shot)) {
                    std::fprintf(stderr, "lightcull-studio: cannot write screenshot %s\n", qPrintable(shot));
                    code = 1;
                } else {
                    const auto run = window.document()->runs().runOutput();
                    std::fprintf(stdout, "screenshot written to %s%s\n", qPrintable(shot),
                                 run && !run->shadedAll.empty() ? " (with the shaded pictures)" : "");
                }
            }
            if (scripted) {
                window.document()->undoStack()->setClean(); // nothing to ask about
                app.exit(code);
            }
        });
    };
    if (!shot.isEmpty() || scripted) {
        if (wantRun) {
            const quint64 target = window.cullService()->lastGeneration();
            // Once: in a shaded image mode, when the pictures have come too.
            auto once = [finish, done = std::make_shared<bool>(false)](bool runOk) {
                if (!std::exchange(*done, true)) finish(runOk);
            };
            QObject::connect(&window, &lcui::MainWindow::runFinished, &window, [&window, once, target](quint64 g) {
                const auto run = window.document()->runs().runOutput();
                const bool pictures = !lcui::CameraView::needsShading(window.cameraView()->imageMode()) ||
                                      (run && !run->shadedAll.empty());
                if (g >= target && pictures) once(true);
            });
            QObject::connect(&window, &lcui::MainWindow::runFailed, &window, [once, target](quint64 g, const QString& m) {
                std::fprintf(stderr, "lightcull-studio: culling failed: %s\n", qPrintable(m));
                if (g >= target) once(false);
            });
        } else {
            finish(true);
        }
    }
    return app.exec();
}
