#include "window/prompts.hpp"

#include <QDialog>
#include <QFileDialog>
#include <QInputDialog>

namespace lcui {

Prompts Prompts::dialogs() {
    Prompts p;
    p.askUnsaved = [](QWidget* parent, const QString& text) {
        return QMessageBox::question(parent, QObject::tr("Unsaved changes"), text,
                                     QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel,
                                     QMessageBox::Save);
    };
    p.showError = [](QWidget* parent, const QString& title, const QString& text) {
        QMessageBox::critical(parent, title, text);
    };
    p.openPath = [](QWidget* parent, const QString& caption, const QString& filter) {
        return QFileDialog::getOpenFileName(parent, caption, {}, filter);
    };
    p.savePath = [](QWidget* parent, const QString& caption, const QString& filter) {
        return QFileDialog::getSaveFileName(parent, caption, {}, filter);
    };
    p.askNumber = [](QWidget* parent, const QString& title, const QString& label, double min, double max,
                     double& value) {
        bool ok = false;
        const double v = QInputDialog::getDouble(parent, title, label, value, min, max, 6, &ok);
        if (ok) value = v;
        return ok;
    };
    p.execDialog = [](QDialog& d) { return d.exec(); };
    return p;
}

} // namespace lcui
