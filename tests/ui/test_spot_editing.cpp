// Spot lights in the studio under Xvfb, driven through real widgets: the "Add
// spot light" action, the property panel's spot fields (kind, direction,
// outer angle) as single undo steps, the refusal of a zero direction, the
// cone drawn in the inspector view (geometry checked and a screenshot written
// to look at), and a culling run with the spot-test parameter set from the
// toolbar, checked against the CLI's library path.
#include "studio_test_support.hpp"
#include "document/document.hpp"
#include "panels/generate_dialog.hpp"
#include "views/inspector_view.hpp"
#include "window/main_window.hpp"
#include "panels/property_panel.hpp"
#include "views/spot_actor.hpp"

#include "culling/core/pipeline.hpp"
#include "culling/math/spot_tests.hpp"

#include <QAction>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QPushButton>
#include <QDialogButtonBox>
#include <QElapsedTimer>
#include <QImage>
#include <QLabel>
#include <QUndoStack>

#include <vtkCellArray.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>

#include <algorithm>
#include <cmath>
#include <memory>

using namespace lcui;

namespace {
}

class SpotEditingTest : public QObject {
    Q_OBJECT
    std::unique_ptr<MainWindow> w_;
    Document* doc() { return w_->document(); }
    template <class T> T* panelField(const char* name) {
        T* f = w_->propertyPanel()->findChild<T*>(name);
        if (!f) qFatal("no field %s", name);
        return f;
    }
    // Adds a spot light through the action (as the menu does) and returns its index.
    int addSpot() {
        const int before = int(doc()->scene().lights.size());
        w_->action("actionAddSpotLight")->trigger();
        return int(doc()->scene().lights.size()) == before + 1 ? before : -1;
    }

private slots:
    void init() {
        w_ = lctest::makeTestWindow();
        QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
        QVERIFY(w_->openBuiltin("wall"));
        QVERIFY(w_->setParamFromUi("width", "320"));
        QVERIFY(w_->setParamFromUi("height", "180"));
    }

    void cleanup() {
        doc()->undoStack()->setClean();
        w_.reset();
    }

    // The Generate lights dialog's spot fields reach the generator: every
    // light a spot (fraction 1) with its outer angle in the chosen range, a
    // mixed fraction gives both kinds, and the range cannot be inverted.
    // Settings the generator refuses (an intensity range upside down) keep
    // the dialog open with the reason, every field as typed.
    void generateDialogKeepsRefusedValues() {
        GenerateLightsDialog dlg(lc::defaultLightGen(doc()->scene(), 200, 3), w_.get());
        auto* fraction = dlg.findChild<QDoubleSpinBox*>("genSpotFraction");
        fraction->setValue(0.5);
        auto* iMin = dlg.findChild<QDoubleSpinBox*>("genIntensityMin");
        auto* iMax = dlg.findChild<QDoubleSpinBox*>("genIntensityMax");
        QVERIFY(iMin && iMax);
        iMin->setValue(20);
        iMax->setValue(10);
        dlg.show();
        QVERIFY(QTest::qWaitForWindowExposed(&dlg));
        auto* ok = dlg.findChild<QDialogButtonBox*>()->button(QDialogButtonBox::Ok);
        QTest::mouseClick(ok, Qt::LeftButton);
        QVERIFY(dlg.isVisible());
        QCOMPARE(dlg.result(), 0);
        auto* error = dlg.findChild<QLabel*>("genError");
        QVERIFY(error && error->isVisible());
        QVERIFY2(error->text().contains("lights.intensity"), qPrintable(error->text()));
        QCOMPARE(fraction->value(), 0.5);
        QCOMPARE(iMin->value(), 20.0);
        iMax->setValue(30);
        QTest::mouseClick(ok, Qt::LeftButton);
        QCOMPARE(dlg.result(), int(QDialog::Accepted));
    }

    void generateDialogMakesSpots() {
        GenerateLightsDialog dlg(lc::defaultLightGen(doc()->scene(), 200, 3), w_.get());
        auto* fraction = dlg.findChild<QDoubleSpinBox*>("genSpotFraction");
        auto* angleMin = dlg.findChild<QDoubleSpinBox*>("genSpotAngleMin");
        auto* angleMax = dlg.findChild<QDoubleSpinBox*>("genSpotAngleMax");
        QVERIFY(fraction && angleMin && angleMax);
        QCOMPARE(fraction->value(), 0.0); // the default stays all point lights
        // Typed as a person types, digit by digit: neither field moves the other.
        dlg.show();
        QVERIFY(QTest::qWaitForWindowExposed(&dlg));
        QApplication::setActiveWindow(&dlg);
        auto type = [](QDoubleSpinBox* box, const char* text) {
            box->setFocus();
            box->selectAll();
            QTest::keyClicks(box, text);
            QTest::keyClick(box, Qt::Key_Tab);
        };
        type(angleMin, "20");
        type(angleMax, "60");
        QCOMPARE(angleMin->value(), 20.0);
        QCOMPARE(angleMax->value(), 60.0);
        // Upside down, the range is refused at OK with the reason, as typed.
        type(angleMin, "35");
        type(angleMax, "20");
        fraction->setValue(1.0);
        QTest::mouseClick(dlg.findChild<QDialogButtonBox*>()->button(QDialogButtonBox::Ok), Qt::LeftButton);
        QVERIFY(dlg.isVisible());
        QVERIFY2(dlg.findChild<QLabel*>("genError")->text().contains("spot_angle"),
                 qPrintable(dlg.findChild<QLabel*>("genError")->text()));
        QCOMPARE(angleMin->value(), 35.0);
        angleMin->setValue(10);
        angleMax->setValue(20);
        fraction->setValue(1.0);
        const std::size_t before = doc()->scene().lights.size();
        QVERIFY(w_->generateLights(dlg.settings()));
        const auto& lights = doc()->scene().lights; // generation appends
        QCOMPARE(lights.size(), before + 200);
        for (std::size_t i = before; i < lights.size(); ++i) {
            const lc::Light& l = lights[i];
            QVERIFY(l.isSpot());
            QVERIFY(l.outerAngleDeg >= 10.0 && l.outerAngleDeg <= 20.0);
        }
        doc()->undoStack()->undo(); // the whole generation is one step
        QCOMPARE(doc()->scene().lights.size(), before);
        fraction->setValue(0.5);
        QVERIFY(w_->generateLights(dlg.settings()));
        QCOMPARE(doc()->scene().lights.size(), before + 200);
        const auto spots = std::count_if(doc()->scene().lights.begin() + std::ptrdiff_t(before),
                                         doc()->scene().lights.end(),
                                         [](const lc::Light& l) { return l.isSpot(); });
        QVERIFY(spots > 50 && spots < 150);
    }

    void addSpotLightIsOneUndoableSpot() {
        const int undoBefore = doc()->undoStack()->count();
        const int i = addSpot();
        QVERIFY(i >= 0);
        const lc::PointLight& l = doc()->scene().lights[std::size_t(i)];
        QVERIFY(l.isSpot());
        QVERIFY(l.validate().empty());
        QCOMPARE(l.outerAngleDeg, 30.0);
        QCOMPARE(doc()->undoStack()->count(), undoBefore + 1);
        QCOMPARE(doc()->selection().currentLight(), i);
        doc()->undoStack()->undo();
        QCOMPARE(int(doc()->scene().lights.size()), i);
    }

    void panelEditsSpotFieldsAsUndoSteps() {
        const int i = addSpot();
        QVERIFY(i >= 0);
        auto* angle = panelField<QDoubleSpinBox>("lightOuterAngle");
        auto* dirX = panelField<QDoubleSpinBox>("lightDirX");
        QVERIFY(angle->isVisible());
        QVERIFY(dirX->isVisible());
        QCOMPARE(angle->value(), 30.0);
        const int steps = doc()->undoStack()->count();
        angle->setValue(12.5); // what committing a typed value does (no keyboard tracking)
        QCOMPARE(doc()->scene().lights[std::size_t(i)].outerAngleDeg, 12.5);
        QCOMPARE(doc()->undoStack()->count(), steps + 1);
        dirX->setValue(0.75);
        QCOMPARE(doc()->scene().lights[std::size_t(i)].direction.x, 0.75);
        QCOMPARE(doc()->undoStack()->count(), steps + 2);
        doc()->undoStack()->undo();
        doc()->undoStack()->undo();
        QCOMPARE(doc()->scene().lights[std::size_t(i)].outerAngleDeg, 30.0);
        QCOMPARE(angle->value(), 30.0); // the panel follows undo
        // The angle field's range is the model's: (0, 90].
        angle->setValue(120);
        QCOMPARE(doc()->scene().lights[std::size_t(i)].outerAngleDeg, 90.0);
    }

    void kindSwitchTogglesSpotFields() {
        const int i = addSpot();
        auto* kind = panelField<QComboBox>("lightKind");
        auto* angle = panelField<QDoubleSpinBox>("lightOuterAngle");
        QCOMPARE(kind->currentText(), QString("spot"));
        kind->setCurrentIndex(kind->findText("point"));
        QVERIFY(!doc()->scene().lights[std::size_t(i)].isSpot());
        QVERIFY(!angle->isVisible());
        doc()->undoStack()->undo();
        QVERIFY(doc()->scene().lights[std::size_t(i)].isSpot());
        QVERIFY(angle->isVisible());
        QCOMPARE(kind->currentText(), QString("spot"));
    }

    void zeroDirectionIsRefused() {
        const int i = addSpot();
        doc()->setLight(i, [&] {
            lc::PointLight l = doc()->scene().lights[std::size_t(i)];
            l.direction = {0, 0, -1};
            return l;
        }());
        const int steps = doc()->undoStack()->count();
        panelField<QDoubleSpinBox>("lightDirZ")->setValue(0.0); // would make (0, 0, 0)
        QVERIFY(doc()->scene().lights[std::size_t(i)].direction == glm::dvec3(0, 0, -1));
        QCOMPARE(doc()->undoStack()->count(), steps);
        QCOMPARE(panelField<QDoubleSpinBox>("lightDirZ")->value(), -1.0);
    }

    void inspectorDrawsTheCone() {
        const int i = addSpot();
        SpotConesActor* cones = w_->inspectorView()->spotCones();
        QVERIFY(cones);
        vtkPolyData* pd = cones->data();
        QVERIFY(pd->GetNumberOfPoints() > 0);
        // The rim lies at the range from the apex, at the outer angle (to the
        // float precision vtkPoints stores).
        const lc::PointLight l = doc()->scene().lights[std::size_t(i)];
        const glm::dvec3 axis = glm::normalize(l.direction);
        double p[3];
        pd->GetPoint(1, p); // point 0 is the apex, 1.. the rim
        const glm::dvec3 d = glm::dvec3(p[0], p[1], p[2]) - l.position;
        QVERIFY(std::abs(glm::length(d) - l.radius()) < 1e-5 * l.radius());
        QVERIFY(std::abs(std::acos(glm::dot(glm::normalize(d), axis)) - glm::radians(l.outerAngleDeg)) < 1e-5);
        // An edit of the angle redraws it.
        panelField<QDoubleSpinBox>("lightOuterAngle")->setValue(60);
        pd = cones->data();
        pd->GetPoint(1, p);
        const glm::dvec3 e = glm::dvec3(p[0], p[1], p[2]) - l.position;
        QVERIFY(std::abs(std::acos(glm::dot(glm::normalize(e), axis)) - glm::radians(60.0)) < 1e-5);
        // Point lights draw no cone.
        auto* kind = panelField<QComboBox>("lightKind");
        kind->setCurrentIndex(kind->findText("point"));
        QCOMPARE(cones->data()->GetNumberOfPoints(), vtkIdType(0));
        kind->setCurrentIndex(kind->findText("spot"));
        // A screenshot to look at: the wall with the spot's cone over it.
        w_->inspectorView()->resetCamera();
        w_->inspectorView()->renderNow();
        QTest::qWait(50);
        w_->inspectorView()->renderNow();
        const QImage shot = w_->inspectorView()->grabFramebuffer();
        QVERIFY(!shot.isNull());
        QDir().mkpath(LC_RENDER_OUT_DIR);
        QVERIFY(shot.save(QString(LC_RENDER_OUT_DIR) + "/spot_cone_inspector.png"));
    }

    void spotTestFromToolbarRunsLikeTheLibrary() {
        const int i = addSpot();
        QVERIFY(i >= 0);
        QVERIFY(w_->setParamFromUi("spot-test", "cone-planes"));
        QVERIFY(doc()->runs().settings().spotTest == lc::SpotTest::ConePlanes);
        const quint64 gen = w_->runCulling();
        QElapsedTimer t;
        t.start();
        while (doc()->runs().runGeneration() < gen && t.elapsed() < lctest::kRunTimeoutMs) QTest::qWait(50);
        QVERIFY(doc()->runs().runGeneration() >= gen);
        auto run = doc()->runs().runOutput();
        QVERIFY(run);
        QVERIFY(run->result.settings.spotTest == lc::SpotTest::ConePlanes);
        QCOMPARE(run->truth.metrics.falseNegatives, std::uint64_t(0));
        QVERIFY(run->lights.isSpot(std::size_t(i)));
        // The same scene and settings through the library give the same lists.
        auto backend = lc::makeBackend("cpu");
        lc::RunOptions opt;
        opt.truthOptions.imageError = false;
        const lc::RunOutput direct = lc::runPipeline(doc()->scene(), doc()->runs().settings(), *backend, opt);
        QVERIFY(direct.result.lightIndices == run->result.lightIndices);
        QCOMPARE(direct.truth.metrics.exactWork, run->truth.metrics.exactWork);
        QVERIFY(direct.truth.metrics.exactWork > 0); // the spot lights the wall
    }
};

LC_STUDIO_TEST_MAIN(SpotEditingTest)
#include "test_spot_editing.moc"
