#pragma once
// Measures how long the camera view's shaded pictures take after the lists,
// in Difference mode (all three images): rounds alternate between moving a
// light as a Live edit does (the lists first, then the ground truth, then a
// whole shading pass) and switching the algorithm between 2.5d and clustered
// (the all-lights image kept, only the culled one shaded). Each round waits
// for its pictures before the next. A benchmark, never a test.

#include <QElapsedTimer>
#include <QObject>
#include <QString>

#include <vector>

namespace lcui {
class MainWindow;
}

struct ShadingReport {
    int lightRounds = 0, algorithmRounds = 0;
    // From the run's lists reaching the views to its pictures shown, median.
    double lightMedianMs = 0, algorithmMedianMs = 0;
    double lightMaxMs = 0, algorithmMaxMs = 0;
    // The culled image's shading time (the slices' sum), median over all rounds.
    double medianCulledShadeMs = 0;
    bool allLightsKeptOnEveryAlgorithmRound = true;
    bool allLightsUpdatedOnEveryLightRound = true; // for the moved light, not shaded from every light
};

class ShadingProbe : public QObject {
    Q_OBJECT
public:
    ShadingProbe(lcui::MainWindow* window, int rounds);
    void start();

signals:
    void done(ShadingReport report);

private:
    void nextRound();
    void onFinished(quint64 generation);
    void finish();

    lcui::MainWindow* window_;
    int rounds_, round_ = 0;
    bool started_ = false;
    quint64 generation_ = 0; // of the round being measured
    double listsAtMs_ = -1;
    QElapsedTimer clock_;
    QString previousMode_;
    std::vector<double> light_, algorithm_, culledShade_;
    ShadingReport report_;
};
