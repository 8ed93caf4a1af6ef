#pragma once
// Culling > Next miss / Previous miss: steps through the shown run's false
// negatives (lc::locateFalseNegatives: the culling test's misses first, then
// list full, then invalid index; most pixels first within each), selecting the
// tile, the light and the list for Explain, as a person hunting a miss would.

#include <QObject>
#include <QString>

#include "culling/custom/custom_cull.hpp"

#include <vector>

class QAction;

namespace lcui {

class Document;

class MissNavigator : public QObject {
    Q_OBJECT
public:
    // The two actions (objectName actionNextMiss / actionPreviousMiss,
    // F8 / Shift+F8), parented to `parent` like the window's others.
    MissNavigator(Document* doc, QObject* parent);
    QAction* nextAction() const { return next_; }
    QAction* previousAction() const { return previous_; }

    // Selects miss `index` (wrapping) of the shown run; false when it has none.
    bool step(int delta);
    // The shown run's misses, located on first use; -1 before a step.
    const std::vector<lc::MissedLight>& misses();
    int current() const { return current_; }

signals:
    // One line for the log and the status bar ("miss 2 of 17: ...").
    void message(const QString& text);
    // A miss was selected: the window shows the Explain panel.
    void missSelected();

private:
    void forget();
    Document* doc_;
    QAction* next_;
    QAction* previous_;
    bool located_ = false;
    std::vector<lc::MissedLight> misses_;
    int current_ = -1;
};

} // namespace lcui
