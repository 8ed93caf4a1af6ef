#pragma once
// The Explain panel: for the selected tile (or cell) and the current light,
// why the light is or is not in that list (lc::explainLight): the
// algorithm's tests with their numbers, and the ground truth of the list's
// pixels. Follows the document's selection and latest run; the explanation
// is the document's (explained_selection.hpp).

#include "culling/diagnostics/explain.hpp"

#include <QWidget>

#include <optional>

class QLabel;
class QPlainTextEdit;

namespace lcui {

class Document;

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
