#include "panels/explain_panel.hpp"

#include "document/document.hpp"


#include <QFontDatabase>
#include <QLabel>
#include <QPlainTextEdit>
#include <QTextOption>
#include <QVBoxLayout>

namespace lcui {

ExplainPanel::ExplainPanel(Document* doc, QWidget* parent) : QWidget(parent), doc_(doc) {
    auto* layout = new QVBoxLayout(this);
    layout->setContentsMargins(4, 4, 4, 4);
    verdict_ = new QLabel;
    verdict_->setObjectName("explainVerdict");
    verdict_->setWordWrap(true);
    text_ = new QPlainTextEdit;
    text_->setObjectName("explainText");
    text_->setReadOnly(true);
    // Wrapped at the dock's width: each test's numbers (signed distance
    // against -r) sit at the end of its line, past a 330 px dock's edge.
    text_->setLineWrapMode(QPlainTextEdit::WidgetWidth);
    text_->setWordWrapMode(QTextOption::WrapAtWordBoundaryOrAnywhere);
    text_->setFont(QFontDatabase::systemFont(QFontDatabase::FixedFont));
    layout->addWidget(verdict_);
    layout->addWidget(text_, 1);
    connect(&doc_->selection(), &Selection::changed, this, &ExplainPanel::refresh);
    connect(&doc_->selection(), &Selection::tileChanged, this, &ExplainPanel::refresh);
    connect(&doc_->runs(), &RunState::runOutputChanged, this, &ExplainPanel::refresh);
    connect(&doc_->runs(), &RunState::runWentStale, this, &ExplainPanel::refresh);
    refresh();
}

void ExplainPanel::refresh() {
    explanation_.reset();
    const ExplainedSelection::Result& explained = doc_->explained();
    std::optional<lc::Explanation> e = explained.explanation;
    const QString error = QString::fromStdString(explained.error);
    if (!e) {
        const auto run = doc_->runs().runOutput();
        const bool selected = doc_->selection().selectedTile() >= 0 && doc_->selection().currentLight() >= 0;
        verdict_->setText(!error.isEmpty()       ? error
                          : doc_->runs().runIsStale() ? tr("The scene changed since the last run: run culling again (F5) "
                                                    "to explain it.")
                          // A Live edit's lists come before their ground truth.
                          : selected && run && !run->truthComputed
                              ? tr("Waiting for the ground truth of run %1 (a Live edit shows its lists first)...")
                                    .arg(doc_->runs().runGeneration())
                              : tr("Select a tile (click the camera view) and a light (the scene tree or "
                                   "a double-click on a row of the tile inspector) to see why the light is, or is not, in "
                                   "that tile's list."));
        verdict_->setStyleSheet({});
        text_->clear();
        return;
    }
    explanation_ = std::move(e);
    const std::size_t light = explanation_->light;
    const std::string name = light < doc_->scene().lights.size() ? doc_->scene().lights[light].name : "";
    text_->setPlainText(QString::fromStdString(explanation_->text(name)));
    verdict_->setText(QString::fromStdString(explanation_->verdict));
    const bool missing = !explanation_->listed && explanation_->pixelsNeeding > 0;
    verdict_->setStyleSheet(missing ? "QLabel { color: white; background: rgb(200,40,40); padding: 2px; }" : "");
}

} // namespace lcui
