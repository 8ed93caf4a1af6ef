#pragma once
// Long work in the status bar: one row per task that is running (a load, the
// shading pass, a report), each with its label, a progress bar and a Cancel
// button. A task appears after a short delay so that quick work does not
// flicker; its progress is a fraction in [0, 1] or "busy" (negative).
//
// While a blocking task runs (runWithProgress: loads, imports, light
// generation) the window takes no other input: an application event filter
// drops mouse, key, wheel, drop and close events except those for the
// status bar's Cancel buttons, so nothing can edit the document under the
// work.

#include <QString>
#include <QWidget>

#include <functional>
#include <map>

class QLabel;
class QProgressBar;
class QTimer;
class QToolButton;

namespace lcui {

class StatusProgress : public QWidget {
    Q_OBJECT
public:
    explicit StatusProgress(QWidget* parent = nullptr);
    ~StatusProgress() override;

    // Starts (or restarts) task `key`: its row shows after `showAfterMs`.
    // `onCancel` runs when the user presses the row's Cancel (empty: no Cancel).
    // Child names, for tests: statusTask_<key> (label), statusProgress_<key>,
    // statusCancel_<key>.
    void begin(const QString& key, const QString& label, std::function<void()> onCancel, int showAfterMs = 300);
    // fraction in [0, 1]; negative: busy without a fraction. `label` empty: unchanged.
    void setProgress(const QString& key, double fraction, const QString& label = {});
    void end(const QString& key);
    bool running(const QString& key) const;
    // The row is on screen (begun and past its delay).
    bool shown(const QString& key) const;

    // Blocks the window's input (see above) until the count returns to 0.
    void blockInput(bool on);
    bool inputBlocked() const { return blockers_ > 0; }

protected:
    bool eventFilter(QObject* watched, QEvent* event) override;

private:
    struct Row {
        QWidget* box = nullptr;
        QLabel* label = nullptr;
        QProgressBar* bar = nullptr;
        QToolButton* cancel = nullptr;
        QTimer* showTimer = nullptr;
        std::function<void()> onCancel;
    };
    std::map<QString, Row> rows_;
    int blockers_ = 0;
};

} // namespace lcui
