#pragma once
// The message log dock's text: one timestamped line per message, marked
// ERROR (an action failed) or WARNING (it went through, with something to
// know), read-only and bounded.

#include <QPlainTextEdit>

namespace lcui {

class MessageLog : public QPlainTextEdit {
    Q_OBJECT
public:
    explicit MessageLog(QWidget* parent = nullptr);
    void log(const QString& message, bool error = false);
    void warn(const QString& message);
};

} // namespace lcui
