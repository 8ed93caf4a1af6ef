#pragma once
// The questions the studio asks a person (unsaved changes, errors, file
// paths, a number): functions the window calls instead of modal dialogs
// directly, so tests and scripts can answer them without a modal loop.

#include <QMessageBox>
#include <QString>

#include <functional>

class QDialog;
class QWidget;

namespace lcui {

struct Prompts {
    // Unsaved changes: Save, Discard or Cancel.
    std::function<QMessageBox::StandardButton(QWidget*, const QString& text)> askUnsaved;
    std::function<void(QWidget*, const QString& title, const QString& text)> showError;
    // File dialogs; an empty string means cancelled.
    std::function<QString(QWidget*, const QString& caption, const QString& filter)> openPath;
    std::function<QString(QWidget*, const QString& caption, const QString& filter)> savePath;
    // A number in [min, max]; false when cancelled.
    std::function<bool(QWidget*, const QString& title, const QString& label, double min, double max, double& value)>
        askNumber;
    // A dialog of the studio's own (QDialog::exec); its result code.
    std::function<int(QDialog&)> execDialog;

    // Each question as a modal dialog (QMessageBox, QFileDialog, QInputDialog).
    static Prompts dialogs();
};

} // namespace lcui
