#pragma once
// The user's culling shader the studio culls with instead of a built-in
// algorithm (Culling > Custom shader...): its options read from the file's
// first line, and the file watched, so that saving it in an editor re-reads
// the options and asks for a run. Editors that save by replacing the file
// are followed to the new one, and a file deleted and written again (git
// checkout, some editors) to its return; a save's burst of changes is one
// run.

#include "culling/custom/custom_cull.hpp"

#include <QObject>
#include <QString>

#include <memory>

class QFileSystemWatcher;
class QTimer;

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
    // The file changed and its settings line is refused (`why`): culling
    // keeps the settings it had, and the run shown is the file's earlier
    // version's. Empty `why`: the file (or another, or none) is in use again.
    void refusalChanged(const QString& why);

private:
    void reload();
    // What tells one version of the file from the next: modified and
    // changed times and size ("" when there is no file).
    static QString stamp(const QString& path);

    std::shared_ptr<const lc::CustomShaderOptions> options_;
    QFileSystemWatcher* watcher_; // the file and its folder
    QTimer* settle_;              // a change is read once the file is quiet
    QString stamp_;               // of the version last read
    bool gone_ = false;           // the file was deleted and not yet back
};

} // namespace lcui
