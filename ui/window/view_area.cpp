#include "window/view_area.hpp"

#include "views/camera_view.hpp"
#include "views/inspector_view.hpp"

#include <QSettings>
#include <QSplitter>
#include <QTabBar>
#include <QVBoxLayout>

namespace lcui {

ViewArea::ViewArea(Document* doc, QWidget* parent) : QWidget(parent) {
    camera_ = new CameraView(doc);
    camera_->setObjectName("cameraView");
    inspector_ = new InspectorView(doc);
    inspector_->setObjectName("inspectorView");
    splitter_ = new QSplitter(Qt::Horizontal);
    splitter_->setObjectName("viewSplitter");
    splitter_->addWidget(camera_);
    splitter_->addWidget(inspector_);
    tabs_ = new QTabBar;
    tabs_->addTab(tr("Camera view"));
    tabs_->addTab(tr("Inspector view"));
    tabs_->setVisible(false);
    connect(tabs_, &QTabBar::currentChanged, this, [this](int i) {
        if (!tabs_->isVisible()) return;
        camera_->setVisible(i == 0);
        inspector_->setVisible(i == 1);
    });
    auto* vl = new QVBoxLayout(this);
    vl->setContentsMargins(0, 0, 0, 0);
    vl->setSpacing(0);
    vl->addWidget(tabs_);
    vl->addWidget(splitter_, 1);
}

void ViewArea::setTabbed(bool tabbed) {
    tabs_->setVisible(tabbed);
    camera_->setVisible(!tabbed || tabs_->currentIndex() == 0);
    inspector_->setVisible(!tabbed || tabs_->currentIndex() == 1);
}

bool ViewArea::tabbed() const { return !tabs_->isHidden(); }

void ViewArea::restore(const QSettings& st) {
    splitter_->restoreState(st.value("window/splitter").toByteArray());
    tabs_->setCurrentIndex(st.value("window/currentView", 0).toInt());
}

void ViewArea::save(QSettings& st) const {
    st.setValue("window/splitter", splitter_->saveState());
    st.setValue("window/currentView", tabs_->currentIndex());
}

} // namespace lcui
