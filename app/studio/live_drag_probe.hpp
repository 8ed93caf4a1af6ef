#pragma once
// Measures Live mode the way a user feels it: one light dragged continuously
// with the inspector view's handle widget (its own interaction events, as a
// mouse drag sends them, at `motionHz`), Live on, for `seconds`. Every
// finished run is a re-cull plus a redraw of both views (they render when the
// document takes the result). Reports the rate of results shown and the
// latency from an edit to its result on screen. A benchmark, never a test.

#include <QObject>
#include <QElapsedTimer>
#include <QTimer>

#include <map>
#include <vector>

namespace lcui {
class MainWindow;
}

struct LiveDragReport {
    int edits = 0;           // handle motion events sent
    int shown = 0;           // runs whose result reached the views
    double seconds = 0;      // from the first edit to the last result
    double medianLatencyMs = 0, maxLatencyMs = 0;
    double medianCullMs = 0, medianDepthMs = 0;
    double medianTruthMs = 0; // of the ground truths that completed (a newer edit cancels one)
    int truths = 0;
    // Where a cycle's time goes on the UI thread: handling one edit (undo
    // command, view updates, scene copy and post), one render of each view.
    double medianEditMs = 0, medianInspectorMs = 0, medianCameraMs = 0;
    // Before the drag: full frames of each view alone (median of 3), no edit.
    double staticInspectorMs = 0, staticCameraMs = 0;
    int inspectorFrames = 0, cameraFrames = 0;
    std::size_t lights = 0;
    int inspectorWidth = 0, inspectorHeight = 0;
    double rateHz() const { return seconds > 0 ? shown / seconds : 0; }
};

class LiveDragProbe : public QObject {
    Q_OBJECT
public:
    LiveDragProbe(lcui::MainWindow* window, double seconds, double motionHz = 60);
    void start();

signals:
    void done(LiveDragReport report);

private:
    void step();
    void onFinished(quint64 generation);
    void finish();
    void onInspectorStart() { inspectorClock_.start(); }
    void onInspectorEnd();
    void onCameraStart() { cameraClock_.start(); }
    void onCameraEnd();

    lcui::MainWindow* window_;
    double seconds_;
    QTimer motion_;
    QElapsedTimer clock_;
    int light_ = 0;
    int edits_ = 0;
    bool stopping_ = false;
    double firstEditMs_ = -1, lastShownMs_ = 0;
    std::map<quint64, double> editAtMs_; // request generation -> time of its edit
    double staticInspectorMs_ = 0, staticCameraMs_ = 0;
    std::vector<double> latencies_, cull_, depth_, truth_, edit_, inspector_, camera_;
    QElapsedTimer inspectorClock_, cameraClock_;
};
