#pragma once
// The Explain panel: for the selected tile (or cell) and the current light,
// why the light is or is not in that list (lc::explainLight): the
// algorithm's tests with their numbers, and the ground truth of the list's
// pixels. Follows the document's selection and latest run.

#include "culling/diagnostics/explain.hpp"

#include <QWidget>

#include <optional>

class QLabel;
class QPlainTextEdit;

namespace lcui {

class Document;

// The explanation of the document's selection: the selected tile (its
// selected cell, or its first list when it has several and none is
// selected) and the current light, in the latest run once its ground truth
// is in. nullopt when something is missing; throws what lc::explainLight throws.
std::optional<lc::Explanation> explainSelection(const Document& doc);

class ExplainPanel : public QWidget {
    Q_OBJECT
public:
    explicit ExplainPanel(Document* doc, QWidget* parent = nullptr);
    // The explanation shown, if any (tests read it).
    const std::optional<lc::Explanation>& explanation() const { return explanation_; }
    QPlainTextEdit* textView() const { return text_; }

private:
    void refresh();

    Document* doc_;
    QLabel* verdict_;
    QPlainTextEdit* text_;
    std::optional<lc::Explanation> explanation_;
};

} // namespace lcui
