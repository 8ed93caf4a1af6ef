#include "work/custom_shader_source.hpp"

#include <QFileInfo>
#include <QFileSystemWatcher>

namespace lcui {

CustomShaderSource::CustomShaderSource(QObject* parent) : QObject(parent), watcher_(new QFileSystemWatcher(this)) {
    connect(watcher_, &QFileSystemWatcher::fileChanged, this, &CustomShaderSource::reload);
}

QString CustomShaderSource::path() const { return options_ ? QString::fromStdString(options_->path) : QString(); }

void CustomShaderSource::set(const QString& path) {
    std::shared_ptr<const lc::CustomShaderOptions> o;
    if (!path.isEmpty())
        o = std::make_shared<const lc::CustomShaderOptions>(lc::shaderOptionsFromFile(path.toStdString()));
    if (!watcher_->files().isEmpty()) watcher_->removePaths(watcher_->files());
    options_ = o;
    if (o) watcher_->addPath(path);
}

void CustomShaderSource::reload() {
    if (!options_) return;
    const QString p = path();
    // Editors often save by replacing the file: watch the new one.
    if (QFileInfo::exists(p) && !watcher_->files().contains(p)) watcher_->addPath(p);
    if (!QFileInfo::exists(p)) return; // mid-save; the new file's change follows
    emit logged(tr("%1 changed: culling again").arg(p), false);
    try {
        // The first line may have changed its settings.
        options_ = std::make_shared<const lc::CustomShaderOptions>(lc::shaderOptionsFromFile(p.toStdString()));
    } catch (const std::exception& e) {
        emit logged(tr("cannot use %1: %2").arg(p, QString::fromStdString(e.what())), true);
        return;
    }
    emit changed();
}

} // namespace lcui
