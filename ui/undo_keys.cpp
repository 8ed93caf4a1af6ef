#include "undo_keys.hpp"

#include <QAbstractSpinBox>
#include <QKeyEvent>
#include <QKeySequence>
#include <QLineEdit>

namespace lcui {

void UndoKeysToWindow::watch(QWidget* field) {
    if (qobject_cast<QAbstractSpinBox*>(field) || qobject_cast<QLineEdit*>(field)) field->installEventFilter(this);
    for (QWidget* w : field->findChildren<QAbstractSpinBox*>()) w->installEventFilter(this);
    for (QWidget* w : field->findChildren<QLineEdit*>()) w->installEventFilter(this);
}

bool UndoKeysToWindow::eventFilter(QObject* watched, QEvent* event) {
    if (event->type() == QEvent::ShortcutOverride) {
        auto* key = static_cast<QKeyEvent*>(event);
        if (key->matches(QKeySequence::Undo) || key->matches(QKeySequence::Redo) ||
            QKeySequence(int(key->modifiers()) | key->key()) == QKeySequence(QStringLiteral("Ctrl+Shift+Z"))) {
            event->ignore(); // not the field's: the window's Undo and Redo actions take it
            return true;
        }
    }
    return QObject::eventFilter(watched, event);
}

} // namespace lcui
