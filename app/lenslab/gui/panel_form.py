"""The property editor's forms: a label beside each field where the panel is wide enough, above it where not.

QFormLayout's own rule (WrapLongRows) keeps a row side by side when the widest label and the field's least width
add up to no more than the form's width, and then gives the field that width less the label column *and the
spacing between them*: a field within the spacing's few pixels of fitting is squeezed below the least it can show
(the Z of a size cut off, a number's last digit). This form sees that coming at the width it is given, and then
puts every label above its field; where nothing would be squeezed it keeps Qt's rule."""

from __future__ import annotations

from PySide6.QtCore import QRect, Qt
from PySide6.QtWidgets import QFormLayout


class PanelForm(QFormLayout):
    def __init__(self, parent=None):
        super().__init__(parent)
        self.setLabelAlignment(Qt.AlignRight | Qt.AlignVCenter)
        self.setFieldGrowthPolicy(QFormLayout.AllNonFixedFieldsGrow)
        self.setRowWrapPolicy(QFormLayout.WrapLongRows)
        self.setHorizontalSpacing(8)
        self.setVerticalSpacing(5)

    def setGeometry(self, rect: QRect) -> None:
        policy = self._policy_for(rect.width())
        if policy != self.rowWrapPolicy():
            self.setRowWrapPolicy(policy)
        super().setGeometry(rect)

    def _policy_for(self, width: int) -> QFormLayout.RowWrapPolicy:
        margins = self.contentsMargins()
        width -= margins.left() + margins.right()
        spacing = max(0, self.horizontalSpacing())
        rows = []
        for row in range(self.rowCount()):
            label, field = self.itemAt(row, QFormLayout.LabelRole), self.itemAt(row, QFormLayout.FieldRole)
            if label is None or field is None or label.isEmpty() or field.isEmpty():
                continue
            rows.append((label.sizeHint().width(), field.minimumSize().width()))
        # Qt's rule, as QFormLayout lays out: the label column is the widest label of the rows that fit without the
        # spacing; a row stays side by side when its label is no wider and its field fits beside it, again without
        # the spacing, and its field is then given the rest less the spacing.
        column = max((lw for lw, fw in rows if lw + fw <= width), default=0)
        beside = [fw for lw, fw in rows if lw <= column and column + fw <= width]
        squeezed = any(width - column - spacing < fw for fw in beside)
        return QFormLayout.WrapAllRows if squeezed else QFormLayout.WrapLongRows


__all__ = ["PanelForm"]
