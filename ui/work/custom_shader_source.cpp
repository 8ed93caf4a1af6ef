#include "work/custom_shader_source.hpp"

#include <QDateTime>
#include <QFileInfo>
#include <QFileSystemWatcher>
#include <QTimer>

namespace lcui {

namespace {
// How long the file must be quiet before it is read: an editor's save
// (truncate, then write; or write a copy, then rename) is one change.
constexpr int kSettleMs = 120;
} // namespace

CustomShaderSource::CustomShaderSource(QObject* parent)
    : QObject(parent), watcher_(new QFileSystemWatcher(this)), settle_(new QTimer(this)) {
    settle_->setSingleShot(true);
    settle_->setInterval(kSettleMs);
    connect(settle_, &QTimer::timeout, this, &CustomShaderSource::reload);
    connect(watcher_, &QFileSystemWatcher::fileChanged, settle_, qOverload<>(&QTimer::start));
    connect(watcher_, &QFileSystemWatcher::directoryChanged, settle_, qOverload<>(&QTimer::start));
}

QString CustomShaderSource::path() const { return options_ ? QString::fromStdString(options_->path) : QString(); }

QString CustomShaderSource::stamp(const QString& path) {
    const QFileInfo fi(path);
    if (!fi.exists()) return {};
    return QString::number(fi.lastModified().toMSecsSinceEpoch()) + ":" + QString::number(fi.size()) + ":" +
           QString::number(fi.metadataChangeTime().toMSecsSinceEpoch());
}

void CustomShaderSource::set(const QString& path) {
    std::shared_ptr<const lc::CustomShaderOptions> o;
    if (!path.isEmpty())
        o = std::make_shared<const lc::CustomShaderOptions>(lc::shaderOptionsFromFile(path.toStdString()));
    settle_->stop();
    if (!watcher_->files().isEmpty()) watcher_->removePaths(watcher_->files());
    if (!watcher_->directories().isEmpty()) watcher_->removePaths(watcher_->directories());
    options_ = o;
    gone_ = false;
    emit refusalChanged({});
    if (!o) return;
    // The file, and its folder: an editor or `git checkout` that deletes the
    // file and writes it anew ends the file's watch, the folder's stays.
    watcher_->addPath(path);
    watcher_->addPath(QFileInfo(path).absolutePath());
    stamp_ = stamp(path);
}

void CustomShaderSource::reload() {
    if (!options_) return;
    const QString p = path();
    if (!QFileInfo::exists(p)) {
        if (!gone_) emit logged(tr("%1 is gone: culling again when it is back").arg(p), false);
        gone_ = true;
        return;
    }
    // Watch the file that is there now (a save by replacing it, or its return).
    if (!watcher_->files().contains(p)) watcher_->addPath(p);
    const QString now = stamp(p);
    // Another file of the folder changed (an editor's swap file): not ours.
    if (now == stamp_ && !gone_) return;
    stamp_ = now;
    gone_ = false;
    emit logged(tr("%1 changed: culling again").arg(p), false);
    try {
        // The first line may have changed its settings.
        options_ = std::make_shared<const lc::CustomShaderOptions>(lc::shaderOptionsFromFile(p.toStdString()));
    } catch (const std::exception& e) {
        emit logged(tr("cannot use %1: %2").arg(p, QString::fromStdString(e.what())), true);
        emit refusalChanged(QString::fromStdString(e.what()));
        return;
    }
    emit refusalChanged({});
    emit changed();
}

} // namespace lcui
