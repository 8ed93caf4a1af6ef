#include "widgets/message_log.hpp"

#include <QDateTime>

namespace lcui {

MessageLog::MessageLog(QWidget* parent) : QPlainTextEdit(parent) {
    setObjectName("messageLog");
    setReadOnly(true);
    setMaximumBlockCount(5000);
}

void MessageLog::log(const QString& message, bool error) {
    appendPlainText(QDateTime::currentDateTime().toString("hh:mm:ss ") + (error ? "ERROR " : "") + message);
}

void MessageLog::warn(const QString& message) {
    appendPlainText(QDateTime::currentDateTime().toString("hh:mm:ss ") + "WARNING " + message);
}

} // namespace lcui
