#pragma once
// Ctrl+Z, Ctrl+Y and Ctrl+Shift+Z typed in an editable field (a spin box, a
// line edit) go to the window's Undo and Redo actions, the scene's undo
// stack, instead of the field's own text undo: focus stays in a field after
// Enter, and the edit the user wants back is the scene's.

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

} // namespace lcui
