// The camera view draws the meshes once per camera, meshes and viewport and
// then shows their read-back picture (what a Live drag redraws is the heat
// map only). What a user would see go wrong: a stale picture after the camera
// moved or the view resized, or frames of one camera that differ. Real widgets under Xvfb, real llvmpipe
// frames. (The picture's anti-aliased edges differ slightly from meshes drawn under the overlay; the render
// baselines, within their tolerance, cover that.)
#include "views/camera_view.hpp"
#include "culling/scene/scene_io.hpp"
#include "document/document.hpp"
#include "studio_test_support.hpp"

#include <QImage>
#include <memory>
#include <vtkRenderer.h>

using namespace lcui;

namespace {
// The letterboxed viewport of the scene (device pixels, Qt rows going down).
QImage viewportOf(CameraView& view, const QImage& shot) {
    const double* vp = view.sceneRenderer()->GetViewport();
    const int w = shot.width(), h = shot.height();
    const QRect r(int(vp[0] * w + 0.5), int((1 - vp[3]) * h + 0.5), int((vp[2] - vp[0]) * w + 0.5),
                  int((vp[3] - vp[1]) * h + 0.5));
    return shot.copy(r).convertToFormat(QImage::Format_RGB32);
}

int differingPixels(const QImage& a, const QImage& b) {
    if (a.size() != b.size()) return a.width() * a.height() + 1;
    int n = 0;
    for (int y = 0; y < a.height(); ++y)
        for (int x = 0; x < a.width(); ++x)
            n += a.pixel(x, y) != b.pixel(x, y);
    return n;
}
} // namespace

class CameraPictureTest : public QObject {
    Q_OBJECT

    std::unique_ptr<Document> doc_;
    std::unique_ptr<CameraView> view_;

    QImage frame() {
        view_->renderNow();
        return viewportOf(*view_, view_->grabFramebuffer());
    }

  private slots:
    void init() {
        doc_ = std::make_unique<Document>();
        lc::Scene scene = lc::makeBuiltinScene("atrium");
        scene.lights.resize(16);
        doc_->resetScene(std::move(scene), {});
        view_ = std::make_unique<CameraView>(doc_.get());
        view_->resize(640, 400);
        view_->show();
        QVERIFY(QTest::qWaitForWindowExposed(view_.get()));
    }

    void cleanup() {
        view_.reset();
        doc_.reset();
    }

    // Light edits and repeated frames reuse the picture: the same pixels.
    void pictureIsReusedWhileOnlyLightsMove() {
        const QImage first = frame();
        const int captures = view_->meshPictureCaptures();
        QVERIFY(captures >= 1);
        const QImage again = frame();
        QCOMPARE(view_->meshPictureCaptures(), captures);
        QCOMPARE(differingPixels(first, again), 0);
        const int drag = doc_->newDragId();
        doc_->moveLight(0, doc_->scene().lights[0].position + glm::dvec3(0.5, 0, 0), drag);
        frame();
        QCOMPARE(view_->meshPictureCaptures(), captures);
    }

    // A camera edit draws the meshes again: the view shows the new camera's
    // image, and going back shows exactly the first image again.
    void cameraEditRedrawsTheMeshes() {
        const QImage before = frame();
        const int captures = view_->meshPictureCaptures();
        const lc::Camera original = doc_->scene().camera;
        lc::Camera moved = original;
        moved.position += glm::dvec3(1.5, 0.5, 0);
        moved.target += glm::dvec3(1.5, 0.5, 0);
        doc_->setCamera(moved);
        const QImage afterMove = frame();
        QCOMPARE(view_->meshPictureCaptures(), captures + 1);
        const int changed = differingPixels(before, afterMove);
        QVERIFY2(changed > before.width() * before.height() / 20,
                 qPrintable(QString("only %1 pixels changed after the camera moved").arg(changed)));
        doc_->setCamera(original);
        const QImage back = frame();
        QCOMPARE(view_->meshPictureCaptures(), captures + 2);
        QCOMPARE(differingPixels(before, back), 0);
        QCOMPARE(differingPixels(back, frame()), 0); // the reused picture of that frame
        QCOMPARE(view_->meshPictureCaptures(), captures + 2);
    }

    // A resize moves and scales the viewport: the picture is taken again at
    // the new size, never stretched or left at the old place.
    void resizeRedrawsTheMeshes() {
        frame();
        const int captures = view_->meshPictureCaptures();
        view_->resize(800, 420);
        QTest::qWait(20);
        const QImage resized = frame();
        QVERIFY(view_->meshPictureCaptures() > captures);
        const int after = view_->meshPictureCaptures();
        QCOMPARE(differingPixels(resized, frame()), 0);
        QCOMPARE(view_->meshPictureCaptures(), after);
    }

    // What a user sees after the view changes size (View > Tabbed views, a
    // dock dragged) with nothing else happening: the frame drawn for the new
    // size, not the old frame (the picture squashed, the legend where it was,
    // and clicks landing on other tiles than the ones drawn under them).
    void aResizeAloneRedrawsForTheNewSize() {
        frame();
        view_->resize(1000, 300);
        QTest::qWait(300); // the event loop only: no renderNow
        const QImage shot = view_->grabFramebuffer().convertToFormat(QImage::Format_RGB32);
        QCOMPARE(shot.width(), view_->width() * int(view_->devicePixelRatio()));
        const double* vp = view_->sceneRenderer()->GetViewport();
        const int x0 = int(vp[0] * shot.width() + 0.5), x1 = int(vp[2] * shot.width() + 0.5);
        // The window background (0.12, 0.12, 0.14) lies left and right of the
        // letterboxed image; the image's own background is darker.
        const QRgb window = shot.pixel(2, shot.height() / 2);
        int first = -1, last = -1;
        const int y = shot.height() / 2;
        for (int x = 0; x < x1 + 40 && x < shot.width(); ++x)
            if (shot.pixel(x, y) != window) {
                if (first < 0) first = x;
                last = x;
            }
        QVERIFY2(std::abs(first - x0) <= 2 && std::abs(last + 1 - x1) <= 2,
                 qPrintable(QString("drawn over columns %1..%2, the viewport is %3..%4").arg(first).arg(last + 1).arg(x0).arg(x1)));
    }

    // The image keeps the camera's aspect, fitted beside the legend band,
    // whatever size the view had while it was hidden (a dock re-laid out
    // while another tab showed, a window resized twice).
    void aViewResizedWhileHiddenFitsItsNewSize() {
        frame();
        for (const QSize size : {QSize(300, 500), QSize(180, 120), QSize(900, 300)}) {
            view_->hide();
            view_->resize(size);
            view_->show();
            QVERIFY(QTest::qWaitForWindowExposed(view_.get()));
            frame();
            const double* vp = view_->sceneRenderer()->GetViewport();
            const double w = view_->width(), h = view_->height();
            const double vw = (vp[2] - vp[0]) * w, vh = (vp[3] - vp[1]) * h;
            const double aspect = doc_->scene().camera.aspect();
            QVERIFY2(std::abs(vw / vh - aspect) < 0.02 * aspect, qPrintable(QString("%1x%2").arg(vw).arg(vh)));
            // Fitted to the room the legend leaves: beside it (as wide as
            // that room or as tall as the view), or under it (as wide as the
            // view or as tall as the room above the legend's band), whichever
            // is the larger image.
            const bool below = view_->legendPlace() == CameraView::LegendPlace::Below;
            const double roomW = below ? w : w - 110, roomH = below ? h - 76 : h;
            QVERIFY2(std::abs(vw - roomW) < 1.5 || std::abs(vh - roomH) < 1.5,
                     qPrintable(QString("%1x%2 in %3x%4").arg(vw).arg(vh).arg(w).arg(h)));
            const double other = below ? std::min(w - 110, (h) * aspect) * std::min(w - 110, h * aspect) / aspect
                                       : std::min(w, (h - 76) * aspect) * std::min(w, (h - 76) * aspect) / aspect;
            QVERIFY2(vw * vh >= other - 1.0, qPrintable(QString("%1x%2 is smaller than the other placement's image")
                                                            .arg(vw).arg(vh)));
        }
    }
};

LC_STUDIO_TEST_MAIN(CameraPictureTest)
#include "test_camera_picture.moc"
