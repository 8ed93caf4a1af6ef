#pragma once
// The user's culling shader the studio culls with instead of a built-in
// algorithm (Culling > Custom shader...): its options read from the file's
// first line, and the file watched, so that saving it in an editor re-reads
// the options and asks for a run. Editors that save by replacing the file
// are followed to the new one.

#include "culling/custom/custom_cull.hpp"

#include <QObject>
#include <QString>

#include <memory>

class QFileSystemWatcher;

namespace lcui {

class CustomShaderSource : public QObject {
    Q_OBJECT
public:
    explicit CustomShaderSource(QObject* parent = nullptr);
    // Culls with the shader at `path` from now on (empty: the built-in
    // algorithm again). On a file it cannot use it throws lc::Error and
    // keeps what it had.
    void set(const QString& path);
    std::shared_ptr<const lc::CustomShaderOptions> options() const { return options_; }
    QString path() const;

signals:
    // The watched file changed and its options were read again: run.
    void changed();
    void logged(const QString& message, bool error);

private:
    void reload();

    std::shared_ptr<const lc::CustomShaderOptions> options_;
    QFileSystemWatcher* watcher_;
};

} // namespace lcui
