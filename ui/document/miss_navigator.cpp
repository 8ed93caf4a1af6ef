#include "document/miss_navigator.hpp"

#include "document/document.hpp"

#include "culling/math/projection.hpp"

#include <QAction>

namespace lcui {

MissNavigator::MissNavigator(Document* doc, QObject* parent) : QObject(parent), doc_(doc) {
    next_ = new QAction(tr("&Next miss"), parent);
    next_->setObjectName("actionNextMiss");
    next_->setShortcut(QKeySequence(Qt::Key_F8));
    next_->setToolTip(tr("Select the next tile and light the culling misses, and explain it (F8)"));
    previous_ = new QAction(tr("&Previous miss"), parent);
    previous_->setObjectName("actionPreviousMiss");
    previous_->setShortcut(QKeySequence(int(Qt::SHIFT) | int(Qt::Key_F8)));
    previous_->setToolTip(tr("Select the previous miss (Shift+F8)"));
    connect(next_, &QAction::triggered, this, [this] { step(+1); });
    connect(previous_, &QAction::triggered, this, [this] { step(-1); });
    connect(&doc_->runs(), &RunState::runOutputChanged, this, &MissNavigator::forget);
    connect(doc_, &Document::sceneReset, this, &MissNavigator::forget);
    connect(&doc_->runs(), &RunState::runWentStale, this, &MissNavigator::forget);
}

void MissNavigator::forget() {
    located_ = false;
    misses_.clear();
    current_ = -1;
}

const std::vector<lc::MissedLight>& MissNavigator::misses() {
    const auto run = doc_->runs().runOutput();
    if (!located_ && run && run->truthComputed && !doc_->runs().runIsStale()) {
        misses_ = lc::locateFalseNegatives(*run, lc::Projection(doc_->scene().camera));
        located_ = true;
    }
    return misses_;
}

bool MissNavigator::step(int delta) {
    const auto run = doc_->runs().runOutput();
    if (!run) {
        emit message(tr("no culling run yet (F5): no misses to show"));
        return false;
    }
    if (doc_->runs().runIsStale()) {
        emit message(tr("the scene changed since the last run: run it again (F5) to find its misses"));
        return false;
    }
    if (!run->truthComputed) {
        emit message(tr("the ground truth of this run is not computed yet: misses are found once it is"));
        return false;
    }
    const std::vector<lc::MissedLight>& all = misses();
    if (all.empty()) {
        emit message(tr("no misses: this run's false negatives are 0"));
        return false;
    }
    const int n = int(all.size());
    current_ = current_ < 0 ? (delta >= 0 ? 0 : n - 1) : ((current_ + delta) % n + n) % n;
    const lc::MissedLight& m = all[std::size_t(current_)];
    const lc::TileGrid& g = run->result.grid;
    doc_->selection().setSelectedTile(int(m.tile));
    doc_->selection().setSelectedLights({int(m.light)});
    doc_->selection().setExplainedList(int(m.list));
    const auto& lights = doc_->scene().lights;
    const QString name = m.light < lights.size() ? QString::fromStdString(lights[m.light].name) : QString();
    emit message(tr("miss %1 of %2: light %3 '%4' in tile %5,%6 (list %7), %8 %9; cause: %10")
                     .arg(current_ + 1)
                     .arg(n)
                     .arg(m.light)
                     .arg(name)
                     .arg(m.tile % g.tilesX)
                     .arg(m.tile / g.tilesX)
                     .arg(m.list)
                     .arg(m.pixels)
                     .arg(m.pixels == 1 ? tr("pixel needs it") : tr("pixels need it"))
                     .arg(QString::fromLatin1(lc::toString(m.cause))));
    emit missSelected();
    return true;
}

} // namespace lcui
