"""The studio's look: a calm dark palette (the picture is the brightest thing on screen), one accent colour,
and line icons drawn from small SVG snippets so that they stay crisp at any scale."""

from __future__ import annotations

from functools import lru_cache

from PySide6.QtCore import QByteArray, QRectF, Qt
from PySide6.QtGui import QColor, QIcon, QPainter, QPalette, QPixmap
from PySide6.QtSvg import QSvgRenderer
from PySide6.QtWidgets import QApplication

from lenslab.color import linear_to_srgb

ACCENT = "#e8a23a"  # selection outline, active tool, focus marks (a warm amber, like Blender's)
FOCUS = "#59d18c"  # depth-of-field overlay and focus readouts
BACKGROUND = "#1e1f21"
PANEL = "#2a2b2e"
BASE = "#232427"
TEXT = "#d6d6d6"
DIM_TEXT = "#8c8f94"

STYLESHEET = f"""
QMainWindow::separator {{ background: {BACKGROUND}; width: 4px; height: 4px; }}
QDockWidget {{ titlebar-close-icon: none; color: {DIM_TEXT}; font-weight: 600; }}
QDockWidget::title {{ background: {BACKGROUND}; padding: 5px 8px; text-align: left; }}
QToolBar {{ background: {PANEL}; border: none; spacing: 2px; padding: 2px 4px; }}
QToolButton {{ border: 1px solid transparent; border-radius: 4px; padding: 3px; }}
QToolButton:hover {{ background: #3a3b3f; }}
QToolButton:checked {{ background: #4a3d28; border-color: {ACCENT}; }}
QStatusBar {{ background: {BACKGROUND}; color: {DIM_TEXT}; }}
QStatusBar QLabel {{ color: {DIM_TEXT}; padding: 0 6px; }}
QTreeView {{ background: {BASE}; border: none; }}
QTreeView::item {{ padding: 2px 0; }}
QTreeView::item:selected {{ background: #4a3d28; color: #ffffff; }}
QScrollArea {{ border: none; background: {PANEL}; }}
QAbstractSpinBox, QLineEdit, QComboBox {{ background: {BASE}; border: 1px solid #3a3b3f; border-radius: 3px;
    padding: 2px 4px; min-height: 18px; }}
QAbstractSpinBox::up-button, QAbstractSpinBox::down-button {{ width: 0px; border: none; }}
QAbstractSpinBox:focus, QLineEdit:focus, QComboBox:focus {{ border-color: {ACCENT}; }}
QPushButton {{ background: #36373b; border: 1px solid #45464b; border-radius: 3px; padding: 4px 10px; }}
QPushButton:hover {{ background: #404146; }}
QPushButton:checked {{ background: #4a3d28; border-color: {ACCENT}; color: #ffffff; }}
QPushButton:disabled {{ color: #5c5e62; background: #2e2f32; border-color: #38393c; }}
QPushButton#lensButton {{ padding: 4px 2px; font-size: 11px; }}
QToolButton#sectionHeader {{ border: none; border-bottom: 1px solid #38393c; border-radius: 0;
    font-weight: 600; color: #c8c8c8; padding: 6px 2px; text-align: left; }}
QToolButton#sectionHeader:hover {{ color: #ffffff; background: transparent; }}
QToolButton#sectionHeader:checked {{ background: transparent; border: none; border-bottom: 1px solid #38393c; }}
QComboBox#apertureCombo {{ font-size: 16px; font-weight: 600; }}
QLabel#bigReadout {{ font-size: 20px; font-weight: 600; color: #f0f0f0; }}
QLabel#readout {{ color: {DIM_TEXT}; }}
QLabel#hint {{ color: {DIM_TEXT}; font-size: 11px; }}
QSlider::groove:horizontal {{ height: 4px; background: #3a3b3f; border-radius: 2px; }}
QSlider::handle:horizontal {{ background: #d6d6d6; width: 12px; margin: -5px 0; border-radius: 6px; }}
QSlider::handle:horizontal:hover {{ background: #ffffff; }}
QSlider::sub-page:horizontal {{ background: #6b5a3e; border-radius: 2px; }}
QSlider::handle:horizontal:disabled {{ background: #5c5e62; }}
QSlider::sub-page:horizontal:disabled {{ background: #3a3b3f; }}
QProgressBar {{ background: {BASE}; border: 1px solid #3a3b3f; border-radius: 3px; text-align: center; height: 12px; }}
QProgressBar::chunk {{ background: #6b5a3e; }}
QMenu::item:selected {{ background: #4a3d28; }}
QToolButton#qt_toolbar_ext_button {{ min-width: 16px; padding: 2px; }}
QToolButton#viewButton {{ background: {BASE}; border: 1px solid #3a3b3f; border-radius: 3px;
    padding: 2px 16px 2px 5px; min-height: 18px; }}
QToolButton#viewButton:hover {{ border-color: #55575c; }}
QToolButton#viewButton::menu-indicator {{ subcontrol-origin: padding; subcontrol-position: right center;
    right: 5px; }}
"""


def apply_theme(app: QApplication) -> None:
    app.setStyle("Fusion")
    p = QPalette()
    for role, colour in (
        (QPalette.Window, PANEL), (QPalette.WindowText, TEXT), (QPalette.Base, BASE),
        (QPalette.AlternateBase, "#27282b"), (QPalette.ToolTipBase, "#3a3b3f"), (QPalette.ToolTipText, TEXT),
        (QPalette.Text, TEXT), (QPalette.Button, "#36373b"), (QPalette.ButtonText, TEXT),
        (QPalette.BrightText, "#ffffff"), (QPalette.Highlight, "#6b5a3e"), (QPalette.HighlightedText, "#ffffff"),
        (QPalette.Link, ACCENT), (QPalette.PlaceholderText, "#6c6f74"),
    ):
        p.setColor(role, QColor(colour))
    for role in (QPalette.Text, QPalette.ButtonText, QPalette.WindowText):
        p.setColor(QPalette.Disabled, role, QColor("#5c5e62"))
    app.setPalette(p)
    app.setStyleSheet(STYLESHEET)


# -- icons ------------------------------------------------------------------------------------------------------
_S = 'fill="none" stroke="{c}" stroke-width="1.6" stroke-linecap="round" stroke-linejoin="round"'
_ICONS = {
    "select": '<path d="M5 3 L5 19 L9.5 14.8 L12.5 21 L15 19.8 L12 13.8 L18 13.5 Z" {s}/>',
    "focus": '<circle cx="12" cy="12" r="7" {s}/><circle cx="12" cy="12" r="1.6" fill="{c}"/>'
             '<path d="M12 2 V6 M12 18 V22 M2 12 H6 M18 12 H22" {s}/>',
    "pan": '<path d="M12 3 V21 M3 12 H21 M12 3 L9.5 5.5 M12 3 L14.5 5.5 M12 21 L9.5 18.5 M12 21 L14.5 18.5 '
           'M3 12 L5.5 9.5 M3 12 L5.5 14.5 M21 12 L18.5 9.5 M21 12 L18.5 14.5" {s}/>',
    "region": '<path d="M4 8 V4 H8 M11 4 H13 M16 4 H20 V8 M20 11 V13 M20 16 V20 H16 M13 20 H11 M8 20 H4 V16 M4 13 V11" {s}/>'
              '<rect x="9" y="9" width="6" height="6" fill="{c}"/>',
    "denoise": '<path d="M3 17 L5 14 L7 18 L9 12 L11 16" {s}/><path d="M13 14 C15 12 17 12 21 14" {s}/>'
               '<path d="M11 6 H17 M14 3 V9" {s}/>',
    "fit": '<path d="M4 9 V4 H9 M15 4 H20 V9 M20 15 V20 H15 M9 20 H4 V15" {s}/><rect x="8" y="8" width="8" height="8" {s}/>',
    "pause": '<path d="M8 5 V19 M16 5 V19" fill="none" stroke="{c}" stroke-width="3" stroke-linecap="round"/>',
    "play": '<path d="M7 4.5 L19 12 L7 19.5 Z" fill="{c}"/>',
    "restart": '<path d="M19 12 A7 7 0 1 1 16.5 6.6" {s}/><path d="M17 2.5 L17 7 L12.5 7" {s}/>',
    "camera": '<rect x="3" y="7" width="18" height="12" rx="2" {s}/><circle cx="12" cy="13" r="3.6" {s}/>'
              '<path d="M8 7 L9.5 4.5 H14.5 L16 7" {s}/>',
    "sphere": '<circle cx="12" cy="12" r="8" {s}/><ellipse cx="12" cy="12" rx="8" ry="3" {s}/>',
    "box": '<path d="M12 3 L20 7.5 V16.5 L12 21 L4 16.5 V7.5 Z M4 7.5 L12 12 L20 7.5 M12 12 V21" {s}/>',
    "rectangle": '<path d="M3 16 L9 7 H21 L15 16 Z" {s}/>',
    "cylinder": '<ellipse cx="12" cy="6" rx="7" ry="2.5" {s}/><path d="M5 6 V18 A7 2.5 0 0 0 19 18 V6" {s}/>',
    "mesh": '<path d="M12 3 L21 18 H3 Z M12 3 L12 13 M3 18 L12 13 L21 18 M7.5 10.5 L12 13 L16.5 10.5" {s}/>',
    "group": '<path d="M3 6 H10 L12 8 H21 V18 H3 Z" {s}/>',
    "light": '<path d="M9 17 H15 M10 20 H14 M12 3 A6 6 0 0 1 15.5 13.8 C14.6 14.6 14.5 15.5 14.5 16 H9.5 '
             'C9.5 15.5 9.4 14.6 8.5 13.8 A6 6 0 0 1 12 3 Z" {s}/>',
    "material": '<circle cx="12" cy="12" r="8" {s}/><path d="M7 9 A6 6 0 0 1 12 6" {s}/>',
    "environment": '<circle cx="12" cy="12" r="8" {s}/><path d="M4 12 H20 M12 4 C8 8 8 16 12 20 '
                   'M12 4 C16 8 16 16 12 20" {s}/>',
    "render": '<rect x="3" y="4" width="18" height="14" rx="1.5" {s}/><path d="M7 21 H17 M8 14 L11 10 L13 12.5 '
              'L15 10.5 L17 14" {s}/>',
    "folder": '<path d="M3 6 H10 L12 8 H21 V18 H3 Z" {s}/>',
    "add": '<path d="M12 5 V19 M5 12 H19" {s}/>',
    "delete": '<path d="M5 7 H19 M10 7 V4.5 H14 V7 M7 7 L8 20 H16 L17 7 M10.5 10.5 V16.5 M13.5 10.5 V16.5" {s}/>',
    "lens": '<circle cx="12" cy="12" r="8.5" {s}/><circle cx="12" cy="12" r="4.5" {s}/>',
    "more": '<path d="M6 6 L12 12 L6 18 M12 6 L18 12 L12 18" {s}/>',
}


@lru_cache(maxsize=None)
def icon(name: str, colour: str = TEXT, size: int = 24) -> QIcon:
    body = _ICONS[name].format(s=_S.format(c=colour), c=colour)
    svg = f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 24 24">{body}</svg>'
    renderer = QSvgRenderer(QByteArray(svg.encode()))
    out = QIcon()
    for scale in (1, 2):
        pixmap = QPixmap(size * scale, size * scale)
        pixmap.fill(Qt.transparent)
        painter = QPainter(pixmap)
        painter.setRenderHint(QPainter.Antialiasing)
        renderer.render(painter, QRectF(0, 0, size * scale, size * scale))
        painter.end()
        pixmap.setDevicePixelRatio(scale)
        out.addPixmap(pixmap)
    # Checked tool buttons show the accent colour.
    if colour == TEXT:
        accent = icon(name, ACCENT, size)
        for mode in (QIcon.Normal, QIcon.Active):
            out.addPixmap(accent.pixmap(size, size), mode, QIcon.On)
    return out


def swatch(rgb, size: int = 14) -> QIcon:
    """A small round colour swatch (materials in the outliner), displayed as the sRGB of a linear colour."""
    r, g, b = (linear_to_srgb(float(c)) for c in rgb)
    pixmap = QPixmap(size * 2, size * 2)
    pixmap.fill(Qt.transparent)
    pixmap.setDevicePixelRatio(2)
    painter = QPainter(pixmap)
    painter.setRenderHint(QPainter.Antialiasing)
    painter.setPen(QColor("#101010"))
    painter.setBrush(QColor.fromRgbF(r, g, b))
    painter.drawEllipse(QRectF(1.5, 1.5, size - 3, size - 3))
    painter.end()
    return QIcon(pixmap)
