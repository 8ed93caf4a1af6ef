#include "widgets/field_events.hpp"

#include <QAbstractSpinBox>
#include <QComboBox>
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

void WheelOnlyWhenFocused::watch(QWidget* panel) {
    for (QWidget* w : panel->findChildren<QAbstractSpinBox*>()) {
        w->setFocusPolicy(Qt::StrongFocus); // not focused by the wheel
        w->installEventFilter(this);
    }
    for (QWidget* w : panel->findChildren<QComboBox*>()) {
        w->setFocusPolicy(Qt::StrongFocus);
        w->installEventFilter(this);
    }
}

bool WheelOnlyWhenFocused::eventFilter(QObject* watched, QEvent* event) {
    if (event->type() == QEvent::Wheel) {
        auto* w = qobject_cast<QWidget*>(watched);
        if (w && !w->hasFocus()) {
            event->ignore(); // unaccepted, it goes on to the parents: the scroll area scrolls
            return true;
        }
    }
    return QObject::eventFilter(watched, event);
}

} // namespace lcui
