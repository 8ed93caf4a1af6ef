#pragma once
// File > Open RenderDoc capture...: the capture, the culling dispatch and the
// description of the renderer's light struct, camera and lists
// (docs/RENDERDOC.md), chosen as a user would in RenderDoc's event browser and
// pipeline state: the capture's dispatches with their marker paths, the
// chosen dispatch's bindings, and a preview of what the description reads
// there (the depth image, the lights' count and first values, the camera,
// the lists) before anything is culled. Open takes the previewed frame.
//
// Reading a capture replays it in a helper process (seconds): the window's
// `Work` runs each read with the status bar's progress.

#include "culling/capture/capture_frame.hpp"

#include <QDialog>

#include <functional>
#include <memory>

class QComboBox;
class QDialogButtonBox;
class QLabel;
class QLineEdit;
class QPlainTextEdit;
class QPushButton;
class QTableWidget;

namespace lcui {

struct Prompts;

class CaptureDialog : public QDialog {
    Q_OBJECT
public:
    // Runs `work` (a capture read) while the window waits; rethrows its error.
    using Work = std::function<void(const QString& label, const std::function<void()>& work)>;
    CaptureDialog(const Prompts& prompts, Work work, QWidget* parent = nullptr);

    // Reads the capture's dispatches (the dispatch list and bindings follow);
    // false, with the error shown in the dialog, for a file that is no
    // readable capture.
    bool setCapture(const QString& path);
    void setDescription(const QString& path);
    // Selects the dispatch whose event id or name/marker text matches.
    bool selectDispatch(const QString& what);
    // Reads the frame at the chosen dispatch with the description; the
    // preview shows it, and Open takes it. False with the error shown.
    bool preview();

    // The previewed frame (null before a successful preview).
    std::shared_ptr<const lc::CaptureFrame> frame() const { return frame_; }
    QString capturePath() const;
    QString descriptionPath() const;
    QString dispatchText() const; // the chosen dispatch's event id, empty when none
    QString errorText() const;    // the last read's error, empty when it worked

private:
    void readBindings();
    void showError(const QString& message);
    void clearPreview();

    const Prompts& prompts_;
    Work work_;
    lc::CaptureInfo info_;
    std::shared_ptr<const lc::CaptureFrame> frame_;
    QLineEdit *capture_, *description_;
    QComboBox* dispatch_;
    QTableWidget* bindings_;
    QLabel *depth_, *error_;
    QPlainTextEdit* echo_;
    QPushButton* previewButton_;
    QDialogButtonBox* buttons_;
};

} // namespace lcui
