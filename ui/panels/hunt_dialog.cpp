#include "panels/hunt_dialog.hpp"

#include <QCheckBox>
#include <QDialogButtonBox>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QRadioButton>
#include <QSpinBox>

namespace lcui {

namespace {
// HuntDim's bits in order, with their --vary names and what each varies.
struct DimRow {
    unsigned bit;
    const char* name;
    const char* tip;
};
const DimRow kDims[6] = {
    {lc::HuntCamera, "camera", "Position and direction around and inside the scene's bounds"},
    {lc::HuntProjection, "projection",
     "Perspective, GL depth, reversed-Z (finite and infinite far), orthographic; field of view, near and far"},
    {lc::HuntScreen, "screen", "Width and height (whole tiles and not, 1x1 up), tile size"},
    {lc::HuntLights, "lights", "Count, positions (behind the camera, across the near plane), radii"},
    {lc::HuntSpots, "spots", "Spot lights up to a 180-degree cone, apex inside a tile, axis along the view"},
    {lc::HuntSceneDim, "scene", "A new generated scene per trial (generated scenes only)"},
};
} // namespace

HuntDialog::HuntDialog(const HuntRequest& r, const QString& underTest, bool sceneHasMeshes, bool customShader,
                       QWidget* parent)
    : QDialog(parent) {
    setWindowTitle(tr("Hunt for a miss"));
    auto* form = new QFormLayout(this);
    auto* what = new QLabel(underTest);
    what->setObjectName("huntUnderTest");
    what->setWordWrap(true);
    form->addRow(tr("Culling under test"), what);

    trials_ = new QSpinBox;
    trials_->setObjectName("huntTrials");
    trials_->setRange(0, 100000000);
    trials_->setValue(int(r.trials));
    trials_->setSpecialValueText(tr("no limit"));
    form->addRow(tr("Trials"), trials_);
    seconds_ = new QDoubleSpinBox;
    seconds_->setObjectName("huntSeconds");
    seconds_->setRange(0, 86400);
    seconds_->setDecimals(0);
    seconds_->setSuffix(tr(" s"));
    seconds_->setValue(r.seconds);
    seconds_->setSpecialValueText(tr("no limit"));
    seconds_->setToolTip(tr("The hunt stops at the first miss, or at whichever limit comes first"));
    form->addRow(tr("Time budget"), seconds_);
    seed_ = new QSpinBox;
    seed_->setObjectName("huntSeed");
    seed_->setRange(0, 2147483647);
    seed_->setValue(int(r.seed));
    seed_->setToolTip(tr("The same seed gives the same trials: a hunt can be repeated exactly"));
    form->addRow(tr("Seed"), seed_);

    auto* dims = new QWidget;
    auto* dl = new QHBoxLayout(dims);
    dl->setContentsMargins(0, 0, 0, 0);
    for (int i = 0; i < 6; ++i) {
        vary_[i] = new QCheckBox(QString::fromLatin1(kDims[i].name));
        vary_[i]->setObjectName(QString("huntVary_") + kDims[i].name);
        vary_[i]->setToolTip(tr(kDims[i].tip));
        vary_[i]->setChecked(r.vary & kDims[i].bit);
        dl->addWidget(vary_[i]);
    }
    form->addRow(tr("Vary"), dims);

    auto* scenes = new QWidget;
    auto* sl = new QHBoxLayout(scenes);
    sl->setContentsMargins(0, 0, 0, 0);
    openScene_ = new QRadioButton(tr("the open scene's meshes"));
    openScene_->setObjectName("huntOpenScene");
    generated_ = new QRadioButton(tr("generated scenes"));
    generated_->setObjectName("huntGenerated");
    openScene_->setEnabled(sceneHasMeshes);
    if (!sceneHasMeshes) openScene_->setToolTip(tr("The open scene has no meshes"));
    (r.openScene && sceneHasMeshes ? openScene_ : generated_)->setChecked(true);
    sl->addWidget(openScene_);
    sl->addWidget(generated_);
    form->addRow(tr("Scenes"), scenes);
    // A new scene per trial only where the scenes are generated.
    auto syncSceneDim = [this] { vary_[5]->setEnabled(!openScene_->isChecked()); };
    connect(openScene_, &QRadioButton::toggled, this, syncSceneDim);
    syncSceneDim();

    overflow_ = new QCheckBox(tr("a list over the layout's capacity is a failure too"));
    overflow_->setObjectName("huntOverflow");
    overflow_->setEnabled(customShader);
    overflow_->setChecked(customShader && r.overflow);
    overflow_->setToolTip(customShader ? tr("Off: a declared capacity (fixed:N) is a limit you chose; such trials "
                                            "are counted apart")
                                       : tr("Custom shaders only: built-in algorithms have no capacity"));
    form->addRow(tr("Overflow"), overflow_);

    auto* folderRow = new QWidget;
    auto* fl = new QHBoxLayout(folderRow);
    fl->setContentsMargins(0, 0, 0, 0);
    folder_ = new QLineEdit(r.folder);
    folder_->setObjectName("huntFolder");
    folder_->setToolTip(tr("The repro goes here: scene.json, scene.glb, repro.sh, summary.json, verdict.txt, run/"));
    auto* browse = new QPushButton(tr("Browse..."));
    connect(browse, &QPushButton::clicked, this, [this] {
        const QString d = QFileDialog::getExistingDirectory(this, tr("Repro folder"), folder_->text());
        if (!d.isEmpty()) folder_->setText(d);
    });
    fl->addWidget(folder_, 1);
    fl->addWidget(browse);
    form->addRow(tr("Repro folder"), folderRow);

    error_ = new QLabel;
    error_->setObjectName("huntError");
    error_->setStyleSheet("color: rgb(200,40,40)");
    error_->setWordWrap(true);
    form->addRow(error_);
    auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel);
    buttons->button(QDialogButtonBox::Ok)->setText(tr("Hunt"));
    connect(buttons, &QDialogButtonBox::accepted, this, &QDialog::accept);
    connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
    form->addRow(buttons);
}

HuntRequest HuntDialog::request() const {
    HuntRequest r;
    r.seed = std::uint64_t(seed_->value());
    r.trials = std::uint64_t(trials_->value());
    r.seconds = seconds_->value();
    r.vary = 0;
    for (int i = 0; i < 6; ++i)
        if (vary_[i]->isChecked()) r.vary |= kDims[i].bit;
    r.openScene = openScene_->isChecked();
    r.overflow = overflow_->isEnabled() && overflow_->isChecked();
    r.folder = folder_->text().trimmed();
    return r;
}

void HuntDialog::accept() {
    const HuntRequest r = request();
    QString why;
    if (r.trials == 0 && r.seconds <= 0)
        why = tr("Give a trial count or a time budget: a hunt without either never ends unless it finds a miss.");
    else if (r.vary == 0 || (r.openScene && r.vary == lc::HuntSceneDim))
        why = tr("Vary at least one thing: every trial would be the same.");
    else if (r.folder.isEmpty())
        why = tr("Choose a repro folder.");
    else if (const std::string p = lc::huntOutputProblem(r.folder.toStdString()); !p.empty())
        why = tr("Repro folder: %1").arg(QString::fromStdString(p));
    error_->setText(why);
    if (why.isEmpty()) QDialog::accept();
}

} // namespace lcui
