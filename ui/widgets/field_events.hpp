#pragma once
// How the studio's editable fields treat the undo keys and the wheel.
//
// Ctrl+Z, Ctrl+Y and Ctrl+Shift+Z typed in a field (a spin box, a line edit)
// go to the window's Undo and Redo actions, the scene's undo stack, instead
// of the field's own text undo: focus stays in a field after Enter, and the
// edit the user wants back is the scene's.

#include <QObject>

class QWidget;

namespace lcui {

class UndoKeysToWindow : public QObject {
public:
    using QObject::QObject;
    // Routes the undo keys of `field` and of every spin box and line edit in it.
    void watch(QWidget* field);

protected:
    bool eventFilter(QObject* watched, QEvent* event) override;
};

// A spin box or combo box inside a scrolling panel takes the mouse wheel
// only once it has focus (a click or Tab): until then the wheel scrolls the
// panel, as a user wheeling past a field to the ones below expects, instead
// of editing whatever field passes under the pointer.
class WheelOnlyWhenFocused : public QObject {
public:
    using QObject::QObject;
    // Every spin box and combo box in `panel`.
    void watch(QWidget* panel);

protected:
    bool eventFilter(QObject* watched, QEvent* event) override;
};

} // namespace lcui
