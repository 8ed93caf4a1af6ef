// The camera view's zoom and pan, and the window's layout at the sizes users
// run it at. What a user would see go wrong: after zooming, the heat map and
// the tile grid no longer over the pixels the meshes show, a click selecting
// another tile than the one under the cursor, a pan that leaves the image,
// the legend or the toolbar's extension arrow eating what they came to see.
// Real widgets under Xvfb: wheel and drag events go through Qt's event path.
#include "views/camera_view.hpp"
#include "document/document.hpp"
#include "window/main_window.hpp"
#include "studio_test_support.hpp"

#include "culling/math/tile_math.hpp"

#include <QAction>
#include <QDir>
#include <QElapsedTimer>
#include <QMouseEvent>
#include <QSplitter>
#include <QToolBar>
#include <QToolButton>
#include <QWheelEvent>

#include <vtkCoordinate.h>
#include <vtkImageData.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>

#include <cmath>
#include <memory>

using namespace lcui;

namespace {

void wheel(QWidget* w, QPoint pos, int delta) {
    QWheelEvent e(QPointF(pos), QPointF(w->mapToGlobal(pos)), QPoint(), QPoint(0, delta), Qt::NoButton,
                  Qt::NoModifier, Qt::NoScrollPhase, false);
    QApplication::sendEvent(w, &e);
}

void drag(QWidget* w, Qt::MouseButton button, QPoint from, QPoint to) {
    QMouseEvent press(QEvent::MouseButtonPress, from, w->mapToGlobal(from), button, button, Qt::NoModifier);
    QApplication::sendEvent(w, &press);
    const QPoint mid = (from + to) / 2;
    QMouseEvent m1(QEvent::MouseMove, mid, w->mapToGlobal(mid), Qt::NoButton, button, Qt::NoModifier);
    QApplication::sendEvent(w, &m1);
    QMouseEvent m2(QEvent::MouseMove, to, w->mapToGlobal(to), Qt::NoButton, button, Qt::NoModifier);
    QApplication::sendEvent(w, &m2);
    QMouseEvent release(QEvent::MouseButtonRelease, to, w->mapToGlobal(to), button, Qt::NoButton, Qt::NoModifier);
    QApplication::sendEvent(w, &release);
}

// Where the 3D camera draws a world point, in widget pixels (y down).
QPointF drawnAt(CameraView& v, const glm::dvec3& p) {
    vtkRenderer* r = v.sceneRenderer();
    r->SetWorldPoint(p.x, p.y, p.z, 1.0);
    r->WorldToDisplay();
    double d[3];
    r->GetDisplayPoint(d);
    const double dpr = v.devicePixelRatioF();
    return {d[0] / dpr, v.height() - d[1] / dpr};
}

// The same point's pixel in the culling image by the library's own
// projection (independent of VTK): x right, y down, in image pixels.
QPointF imagePixelOf(const lc::Camera& c, const glm::dvec3& p) {
    const glm::dvec3 view = glm::dvec3(c.viewFromWorld() * glm::dvec4(p, 1.0));
    if (view.z >= -c.nearPlane) return {-1, -1}; // behind the camera
    const glm::dvec2 px = lc::Projection(c).pixelFromView(view);
    return {px.x, px.y};
}

} // namespace

class CameraZoomTest : public QObject {
    Q_OBJECT
    std::unique_ptr<MainWindow> w_;
    CameraView* view() const { return w_->findChild<CameraView*>("cameraView"); }
    Document* doc() const { return w_->document(); }

    // Widget position of an image pixel at the view's zoom and pan: where
    // the view says the whole zoomed image lies (its size is checked against
    // the zoom in the tests).
    QPointF widgetPosOf(QPointF px) const {
        const lc::Camera& c = doc()->scene().camera;
        const QRectF img = view()->zoomedImageRect();
        return {img.left() + px.x() / c.width * img.width(), img.top() + px.y() / c.height * img.height()};
    }

private slots:
    void init() {
        w_ = lctest::makeTestWindow(QSize(1400, 850));
        QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
        QVERIFY(lctest::openBuiltinWith(*w_, "atrium", {{"width", "320"}, {"height", "180"}}));
        QVERIFY(lctest::waitRun(*w_, w_->runCulling(), true));
        view()->renderNow();
    }
    void cleanup() {
        doc()->undoStack()->setClean();
        w_.reset();
    }

    // The wheel zooms about the cursor: the tile under it stays under it, and
    // the meshes (VTK's camera), the tiles (picking) and the library's own
    // projection agree on where a light's centre is at every zoom.
    void wheelZoomsAboutTheCursorAndEverythingStaysRegistered() {
        CameraView* v = view();
        QCOMPARE(v->zoom(), 1.0);
        const QRect r = v->imageRect();
        // On the middle row: in a direction where the zoomed image is still
        // smaller than the room it is centred (as image viewers do), so
        // only the middle row keeps its place there.
        const QPoint cursor(r.left() + r.width() / 3, r.center().y());
        const int tileBefore = v->tileAtWidgetPos(cursor);
        QVERIFY(tileBefore >= 0);
        wheel(v, cursor, 3 * 120);
        QVERIFY2(std::abs(v->zoom() - std::pow(1.25, 3)) < 1e-9, qPrintable(QString::number(v->zoom())));
        // The image grew by the zoom, and over the room beside the legend:
        // the viewport is larger than the letterbox it started in.
        QVERIFY(std::abs(v->zoomedImageRect().width() - std::pow(1.25, 3) * r.width()) <= 1.5 * std::pow(1.25, 3));
        QVERIFY(v->imageRect().width() * v->imageRect().height() > r.width() * r.height());
        QCOMPARE(v->tileAtWidgetPos(cursor), tileBefore);
        wheel(v, cursor, 4 * 120);
        QCOMPARE(v->tileAtWidgetPos(cursor), tileBefore);
        // Registration: every light centre in front of the camera is drawn
        // by VTK where the library's projection puts its pixel.
        const lc::Camera& cam = doc()->scene().camera;
        int checked = 0;
        for (const auto& l : doc()->scene().lights) {
            const QPointF px = imagePixelOf(cam, l.position);
            if (px.x() < 1 || px.y() < 1 || px.x() > cam.width - 1 || px.y() > cam.height - 1) continue;
            const QPointF expect = widgetPosOf(px);
            if (!QRectF(r).contains(expect)) continue; // zoomed out of the view
            const QPointF got = drawnAt(*v, l.position);
            // VTK draws with the aspect of the viewport rounded to whole
            // pixels, which differs from the image's by up to 1/300: a
            // quarter of an image pixel at the view's edge (a zoom or pan
            // gone wrong is off by many image pixels).
            const double tolerance = std::max(1.0, 0.25 * v->zoomedImageRect().width() / cam.width);
            QVERIFY2(std::hypot(got.x() - expect.x(), got.y() - expect.y()) < tolerance,
                     qPrintable(QString("light %1 drawn at %2,%3, its pixel at %4,%5 (zoom %6)")
                                    .arg(QString::fromStdString(l.name))
                                    .arg(got.x()).arg(got.y()).arg(expect.x()).arg(expect.y()).arg(v->zoom())));
            // And a click there picks the tile of that pixel.
            const lc::TileGrid g = lc::TileGrid::make(cam.width, cam.height, cam.tileSize);
            const QPoint at(int(std::floor(expect.x())), int(std::floor(expect.y())));
            const int tile = v->tileAtWidgetPos(at);
            const auto tx = std::uint32_t(px.x()) / cam.tileSize, ty = std::uint32_t(px.y()) / cam.tileSize;
            // The floor of the widget position can sit one screen pixel off
            // the light's pixel: it is the same tile or a neighbour.
            QVERIFY(tile >= 0);
            QVERIFY2(std::abs(int(tile % g.tilesX) - int(tx)) <= 1 && std::abs(int(tile / g.tilesX) - int(ty)) <= 1,
                     qPrintable(QString("tile %1 for pixel %2,%3").arg(tile).arg(px.x()).arg(px.y())));
            ++checked;
        }
        QVERIFY2(checked >= 3, qPrintable(QString("only %1 lights in view to check").arg(checked)));
        // The caption says the zoom and the way back.
        v->renderNow();
    }

    // A click on the zoomed image selects the tile drawn under the cursor.
    void clickOnTheZoomedImageSelectsTheTileUnderTheCursor() {
        CameraView* v = view();
        const QRect r = v->imageRect();
        v->setZoom(8.0, QPointF(0.7, 0.4));
        const lc::Camera& cam = doc()->scene().camera;
        // Image pixel (230, 110) is inside the 8x window centred at (224, 108).
        const QPointF px(230.5, 110.5);
        QVERIFY(QRectF(r).contains(widgetPosOf(px)));
        const QPoint at = widgetPosOf(px).toPoint();
        QTest::mouseClick(v, Qt::LeftButton, Qt::NoModifier, at);
        const lc::TileGrid g = lc::TileGrid::make(cam.width, cam.height, cam.tileSize);
        QCOMPARE(doc()->selection().selectedTile(), int(g.tileOfPixel(230, 110)));
    }

    // A right or middle drag pans by what the mouse moved, and never out of
    // the image; Ctrl+0 (View > Fit camera image) and a middle double-click fit.
    void dragPansWithinTheImageAndFitRestores() {
        CameraView* v = view();
        const QRect r = v->imageRect();
        v->setZoom(4.0, QPointF(0.5, 0.5));
        const QRectF img = v->zoomedImageRect();
        QVERIFY(std::abs(img.width() - 4 * r.width()) <= 4 * 1.5);
        const QPoint mid = r.center();
        drag(v, Qt::RightButton, mid, mid + QPoint(40, -20));
        // 40 px right on an image img.width() wide: the centre moves
        // 40 / width of the image to the left (and 20 px up, down the image).
        QVERIFY(std::abs(v->viewCentre().x() - (0.5 - 40.0 / img.width())) < 1e-9);
        QVERIFY(std::abs(v->viewCentre().y() - (0.5 - 20.0 / img.height())) < 1e-9);
        QCOMPARE(doc()->selection().selectedTile(), -1); // a pan is not a click
        drag(v, Qt::MiddleButton, mid, mid + QPoint(10 * r.width(), 10 * r.height()));
        // Clamped: the image's top-left corner stops at the viewport's.
        QVERIFY(std::abs(v->zoomedImageRect().left() - v->imageRect().left()) <= 1.0);
        QVERIFY(std::abs(v->zoomedImageRect().top() - v->imageRect().top()) <= 1.0);
        w_->action("actionFitCameraImage")->trigger();
        QCOMPARE(v->zoom(), 1.0);
        QCOMPARE(v->viewCentre(), QPointF(0.5, 0.5));
        v->setZoom(3.0, QPointF(0.3, 0.3));
        QTest::mouseDClick(v, Qt::MiddleButton, Qt::NoModifier, mid);
        QCOMPARE(v->zoom(), 1.0);
        // Zooming out past the whole image stops at the whole image.
        wheel(v, mid, -5 * 120);
        QCOMPARE(v->zoom(), 1.0);
    }

    // In Difference mode the picture is zoomed with the tiles: the pixel the
    // view shows under a tile's centre is that picture pixel.
    void shadedPictureZoomsWithTheTiles() {
        CameraView* v = view();
        v->setImageMode(CameraView::ImageMode::ShadedAll);
        QVERIFY(lctest::waitRun(*w_, w_->runCulling(), true));
        QElapsedTimer t;
        t.start();
        while (!v->shownImage() && t.elapsed() < lctest::kRunTimeoutMs) QTest::qWait(50);
        QVERIFY(v->shownImage());
        v->setZoom(16.0, QPointF(0.45, 0.55));
        v->renderNow();
        const QImage shot = v->grabFramebuffer().convertToFormat(QImage::Format_RGB32);
        const double dpr = v->devicePixelRatioF();
        vtkImageData* pic = v->shownImage();
        int dims[3];
        pic->GetDimensions(dims);
        int compared = 0, matched = 0;
        // The 16x window centred at image pixel (144, 81) spans x 134..154, y 75..87.
        for (int py = 77; py <= 85; py += 2)
            for (int pxl = 136; pxl <= 152; pxl += 3) {
                const QPointF at = widgetPosOf(QPointF(pxl + 0.5, py + 0.5));
                if (!QRectF(v->imageRect()).contains(at)) continue;
                const QRgb s = shot.pixel(int(at.x() * dpr), int(at.y() * dpr));
                const auto* p = static_cast<unsigned char*>(pic->GetScalarPointer(pxl, dims[1] - 1 - py, 0));
                ++compared;
                matched += std::abs(qRed(s) - p[0]) <= 2 && std::abs(qGreen(s) - p[1]) <= 2 &&
                           std::abs(qBlue(s) - p[2]) <= 2;
            }
        QVERIFY2(compared >= 12, qPrintable(QString::number(compared)));
        QVERIFY2(matched == compared, qPrintable(QString("%1 of %2 pixels match the picture").arg(matched).arg(compared)));
        v->setImageMode(CameraView::ImageMode::Heat);
    }

    // At 1280x720 and 1920x1080: every toolbar control is on screen (no
    // extension arrow), the legend sits beside or under the image and never
    // over it, the image takes the whole width or height the legend leaves,
    // and the caption fits. The screenshots are written for a person to look at.
    void layoutHoldsAt1280x720And1920x1080_data() {
        QTest::addColumn<QSize>("size");
        QTest::newRow("1280x720") << QSize(1280, 720);
        QTest::newRow("1920x1080") << QSize(1920, 1080);
    }
    void layoutHoldsAt1280x720And1920x1080() {
        QFETCH(QSize, size);
        w_->resize(size);
        QTest::qWait(100);
        QVERIFY(lctest::waitRun(*w_, w_->runCulling(), true));
        QCoreApplication::processEvents();
        for (QToolBar* bar : w_->findChildren<QToolBar*>()) {
            if (!bar->isVisible()) continue;
            auto* ext = bar->findChild<QToolButton*>("qt_toolbar_ext_button");
            QVERIFY2(!ext || !ext->isVisible(),
                     qPrintable(QString("%1 hides controls behind its arrow at %2x%3")
                                    .arg(bar->objectName())
                                    .arg(size.width())
                                    .arg(size.height())));
        }
        for (const char* name : {"param_height", "backendCombo", "deviceEdit"}) {
            auto* wid = w_->findChild<QWidget*>(name);
            QVERIFY2(wid && wid->isVisible(), name);
        }
        CameraView* v = view();
        v->renderNow();
        const QRect img = v->imageRect();
        const bool below = v->legendPlace() == CameraView::LegendPlace::Below;
        // The image fills the room the legend leaves in one direction.
        if (below)
            QVERIFY2(img.width() >= v->width() - 2 || img.height() >= v->height() - 76 - 2,
                     qPrintable(QString("image %1x%2 in %3x%4").arg(img.width()).arg(img.height()).arg(v->width()).arg(v->height())));
        else
            QVERIFY2(img.height() >= v->height() - 2 || img.width() >= v->width() - 110 - 2,
                     qPrintable(QString("image %1x%2 in %3x%4").arg(img.width()).arg(img.height()).arg(v->width()).arg(v->height())));
        // The legend's box is outside the image.
        vtkScalarBarActor* bar = v->legend();
        QVERIFY(bar->GetVisibility());
        const double* p = bar->GetPositionCoordinate()->GetValue();
        const QRectF legendBox(p[0] * v->width(), (1 - p[1] - bar->GetHeight()) * v->height(),
                               bar->GetWidth() * v->width(), bar->GetHeight() * v->height());
        QVERIFY2(!legendBox.intersects(QRectF(img).adjusted(1, 1, -1, -1)),
                 qPrintable(QString("legend %1,%2 %3x%4 over the image %5,%6 %7x%8")
                                .arg(legendBox.x()).arg(legendBox.y()).arg(legendBox.width()).arg(legendBox.height())
                                .arg(img.x()).arg(img.y()).arg(img.width()).arg(img.height())));
        QDir().mkpath(LC_RENDER_OUT_DIR);
        const QString out = QString(LC_RENDER_OUT_DIR) + QString("/studio_%1x%2.png").arg(size.width()).arg(size.height());
        QVERIFY(w_->grab().save(out));
        // Zoomed in on the busiest part, for the eye.
        v->setZoom(4.0, QPointF(0.5, 0.5));
        v->renderNow();
        QVERIFY(v->grabFramebuffer().save(QString(LC_RENDER_OUT_DIR) +
                                          QString("/camera_zoom_%1x%2.png").arg(size.width()).arg(size.height())));
    }
};

LC_STUDIO_TEST_MAIN(CameraZoomTest)
#include "test_camera_zoom.moc"
