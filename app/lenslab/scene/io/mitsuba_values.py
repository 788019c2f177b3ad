"""Values of the Mitsuba 3 scene format, as plain numbers: transforms, colours and spectra.

The XML reader (:mod:`lenslab.scene.io.mitsuba_xml`) turns elements into calls to these functions; nothing
here knows about XML, files or warnings, so each conversion can be tested on its own.

Transforms follow Mitsuba's ``Transform4f`` (``include/mitsuba/core/transform.h``): a ``<transform>`` starts
at the identity and every operation inside it is multiplied on the **left** (``M = op @ M``), so the first
operation listed is the first applied to a point. ``lookat`` builds the frame (left, up, dir, origin) as
columns, ``matrix`` is given row by row.
"""

from __future__ import annotations

import math
import re

import numpy as np

from lenslab.limits import LARGEST_NUMBER
from lenslab.scene.transform import Transform

RGB = tuple[float, float, float]


# ---------------------------------------------------------------------------------------------------------
# Transforms
# ---------------------------------------------------------------------------------------------------------
def translate_matrix(v) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = v
    return m


def scale_matrix(v) -> np.ndarray:
    return np.diag([float(v[0]), float(v[1]), float(v[2]), 1.0])


def rotate_matrix(axis, angle_deg: float) -> np.ndarray:
    """Mitsuba 3's ``rotate``: ``(1 - cos) a a^T + cos I + sin [a]x``, counter-clockwise about ``a``.

    Mitsuba 3 does **not** normalise the axis (measured with Mitsuba 3.9.1: ``<rotate x="2" angle="33"/>``
    has a determinant of 2.8), so an axis that is not of unit length rotates *and* scales; we do the same, so
    that the geometry is where Mitsuba puts it. For a unit axis this is the usual rotation.
    """
    a = np.asarray(axis, dtype=float)
    if not np.any(a):
        raise ValueError("rotation axis cannot be zero")
    t = math.radians(angle_deg)
    c, s = math.cos(t), math.sin(t)
    x, y, z = a
    cross = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    m = np.eye(4)
    m[:3, :3] = (1 - c) * np.outer(a, a) + c * np.eye(3) + s * cross
    return m


def coordinate_system(n) -> np.ndarray:
    """A unit vector perpendicular to unit ``n`` (Duff et al. 2017), Mitsuba's choice of an absent ``up``."""
    x, y, z = n
    sign = math.copysign(1.0, z)
    a = -1.0 / (sign + z)
    b = x * y * a
    return np.array([1.0 + sign * x * x * a, sign * b, -sign * x])


def lookat_matrix(origin, target, up=None) -> np.ndarray:
    """Mitsuba's ``look_at``: local +Z towards ``target``, +Y up, +X to the *left* of the image."""
    origin = np.asarray(origin, dtype=float)
    direction = np.asarray(target, dtype=float) - origin
    if np.linalg.norm(direction) == 0:
        raise ValueError("lookat origin and target coincide")
    direction /= np.linalg.norm(direction)
    up = np.zeros(3) if up is None else np.asarray(up, dtype=float)
    if not np.any(up):
        up = coordinate_system(direction)
    left = np.cross(up, direction)
    if np.linalg.norm(left) < 1e-12:
        raise ValueError("lookat up is parallel to the view direction")
    left /= np.linalg.norm(left)
    new_up = np.cross(direction, left)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = left, new_up, direction, origin
    return m


def matrix_from_values(values: list[float]) -> np.ndarray:
    """``<matrix value="...">``: 16 numbers (4x4) or 9 (the linear part), row by row."""
    m = np.eye(4)
    if len(values) == 16:
        m[:, :] = np.reshape(values, (4, 4))
    elif len(values) == 9:
        m[:3, :3] = np.reshape(values, (3, 3))
    else:
        raise ValueError(f"matrix must have 9 or 16 values, got {len(values)}")
    return m


def euler_xyz_deg(r: np.ndarray) -> tuple[float, float, float]:
    """Angles (degrees) of :class:`Transform`'s rotation ``Rz @ Ry @ Rx`` equal to the proper rotation ``r``."""
    cy = math.hypot(r[0, 0], r[1, 0])
    ay = math.atan2(-r[2, 0], cy)
    if cy > 1e-12:
        ax = math.atan2(r[2, 1], r[2, 2])
        az = math.atan2(r[1, 0], r[0, 0])
    else:  # gimbal lock (y = +-90 degrees): only x -+ z is defined; put it all in x
        ax = math.atan2(-r[1, 2], r[1, 1])
        az = 0.0
    return math.degrees(ax), math.degrees(ay), math.degrees(az)


def _clean(values) -> tuple[float, float, float]:
    """Plain floats, with -0.0 and 1e-17-size rounding noise tidied so saved scenes read well."""
    out = []
    for v in values:
        v = float(v)
        r = round(v, 12)
        out.append(0.0 if r == 0 else (r if abs(r - v) < 1e-12 else v))
    return tuple(out)  # type: ignore[return-value]


def _trs(translate, rotation: np.ndarray, scale) -> Transform:
    return Transform(translate=_clean(translate), rotate_deg=_clean(euler_xyz_deg(rotation)), scale=_clean(scale))


def decompose_affine(m: np.ndarray, tolerance: float = 1e-9) -> list[Transform]:
    """Node transforms (outermost first) whose product is the affine matrix ``m``, exactly.

    A matrix without shear (rotation, axis scale, mirror, translation: columns of the linear part orthogonal)
    becomes one ``T @ R @ S``. Any other invertible matrix becomes two, through the singular value
    decomposition ``A = U diag(s) V^T``: an outer ``T @ U @ diag(s)`` and an inner rotation ``V^T``.
    Raises ValueError for a singular matrix (a scale of zero flattens the shape to nothing).
    """
    m = np.asarray(m, dtype=float)
    if not np.allclose(m[3], [0, 0, 0, 1], atol=1e-12):
        raise ValueError("a projective matrix (last row not 0 0 0 1) is not a placement")
    a = m[:3, :3]
    t = m[:3, 3]
    scale = np.linalg.norm(a, axis=0)
    if scale.min() <= 1e-12 * max(scale.max(), 1.0) or abs(np.linalg.det(a)) < 1e-30:
        raise ValueError("singular transform (a scale of zero)")
    r = a / scale
    if np.linalg.det(r) < 0:  # a mirror: carry it as a negative scale along x
        scale[0] = -scale[0]
        r[:, 0] = -r[:, 0]
    single = _trs(t, r, scale)
    if np.allclose(single.matrix(), m, rtol=0, atol=tolerance * max(1.0, np.abs(m).max())):
        return [single]
    u, s, vt = np.linalg.svd(a)
    if np.linalg.det(u) < 0:
        u[:, 2], s[2] = -u[:, 2], -s[2]
    if np.linalg.det(vt) < 0:
        vt[2, :], s[2] = -vt[2, :], -s[2]
    return [_trs(t, u, s), _trs((0, 0, 0), vt, (1, 1, 1))]


def compose(transforms: list[Transform]) -> np.ndarray:
    m = np.eye(4)
    for t in transforms:
        m = m @ t.matrix()
    return m


def nearest_similarity(m: np.ndarray) -> np.ndarray:
    """The rotation-plus-uniform-scale matrix closest to ``m`` (polar decomposition), same translation."""
    a = m[:3, :3]
    u, s, vt = np.linalg.svd(a)
    r = u @ vt
    out = np.eye(4)
    out[:3, :3] = r * abs(np.linalg.det(a)) ** (1 / 3)
    out[:3, 3] = m[:3, 3]
    return out


# ---------------------------------------------------------------------------------------------------------
# Numbers, colours and spectra
# ---------------------------------------------------------------------------------------------------------
_SPLIT = re.compile(r"[\s,]+")


class NumberTooLarge(ValueError):
    """A number that reads, but beyond limits.LARGEST_NUMBER: said as it is, not as a number that did not parse."""


def parse_number(text: str) -> float:
    """One number of a scene file. Mitsuba would take "nan" or "inf" as well; nothing in a scene has a use
    for them, and one would reach the GPU as a pixel that never converges, so they are refused here; so is a
    number beyond the bound of every scene's numbers (limits.LARGEST_NUMBER, as native scenes): a radiance of
    1e308 is finite in Python and infinite in the float32 light tables."""
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"'{text.strip()}' is not a finite number")
    if abs(value) > LARGEST_NUMBER:
        raise NumberTooLarge(f"'{text.strip()}' is too large (the most any value may be is {LARGEST_NUMBER:g})")
    return value


def split_numbers(text: str) -> list[float]:
    """Numbers separated by commas and/or white space, as Mitsuba's ``string::tokenize``."""
    tokens = [t for t in _SPLIT.split(text.strip()) if t]
    return [parse_number(t) for t in tokens]


def _lobe(lam: np.ndarray, mu: float, s1: float, s2: float) -> np.ndarray:
    s = np.where(lam < mu, s1, s2)
    return np.exp(-0.5 * ((lam - mu) / s) ** 2)


def cie1931_xyz(lam: np.ndarray) -> np.ndarray:
    """CIE 1931 2-degree colour matching functions, (N, 3), from the multi-lobe fit of Wyman, Sloan and
    Shirley (JCGT 2013); within about 1% of the tables, which is plenty for turning a spectrum into a colour."""
    lam = np.asarray(lam, dtype=float)
    x = 1.056 * _lobe(lam, 599.8, 37.9, 31.0) + 0.362 * _lobe(lam, 442.0, 16.0, 26.7) - 0.065 * _lobe(lam, 501.1, 20.4, 26.2)
    y = 0.821 * _lobe(lam, 568.8, 46.9, 40.5) + 0.286 * _lobe(lam, 530.9, 16.3, 31.1)
    z = 1.217 * _lobe(lam, 437.0, 11.8, 36.0) + 0.681 * _lobe(lam, 459.0, 26.0, 13.8)
    return np.stack([x, y, z], axis=-1)


XYZ_TO_LINEAR_SRGB = np.array(
    [[3.2404542, -1.5371385, -0.4985314], [-0.9692660, 1.8760108, 0.0415560], [0.0556434, -0.2040259, 1.0572252]]
)
CIE_MIN_NM, CIE_MAX_NM = 360.0, 830.0
_LAMBDA = np.arange(CIE_MIN_NM, CIE_MAX_NM + 0.5, 1.0)
_CMF = cie1931_xyz(_LAMBDA)


def _planck(lam_nm: np.ndarray, kelvin: float) -> np.ndarray:
    lam = lam_nm * 1e-9
    return 1.0 / (lam**5 * np.expm1(1.4387769e-2 / (lam * kelvin)))


# Reflectances are seen under a daylight white (a 6504 K black body standing in for D65's table), so that a
# flat spectrum is neutral; emission spectra are absolute, as Mitsuba 3's RGB variants read them: XYZ with
# Y normalised by the area under y-bar, then sRGB, so a flat emission spectrum comes out slightly warm.
_DAYLIGHT_CMF = _CMF * (_planck(_LAMBDA, 6504.0) / _planck(_LAMBDA, 6504.0).mean())[:, None]
_DAYLIGHT_WHITE = XYZ_TO_LINEAR_SRGB @ _DAYLIGHT_CMF.sum(axis=0)
_Y_INTEGRAL = _CMF[:, 1].sum()
EQUAL_ENERGY_RGB: RGB = tuple(float(c) for c in XYZ_TO_LINEAR_SRGB @ _CMF.sum(axis=0) / _Y_INTEGRAL)  # type: ignore[assignment]


def parse_spectrum(text: str) -> list[tuple[float, float]] | float:
    """A ``<spectrum value>``: one number (a uniform spectrum) or ``wavelength:value`` pairs."""
    text = text.strip()
    if ":" not in text:
        values = split_numbers(text)
        if len(values) != 1:
            raise ValueError(f"expected one value or wavelength:value pairs, got '{text}'")
        return values[0]
    pairs = []
    for item in (t for t in re.split(r"[,\s]+", text) if t):
        if item.count(":") != 1:
            raise ValueError(f"'{item}' is not a wavelength:value pair")
        w, v = item.split(":")
        pairs.append((parse_number(w), parse_number(v)))
    pairs.sort()
    if len(pairs) < 2:
        raise ValueError("a sampled spectrum needs at least two wavelength:value pairs")
    return pairs


def spectrum_to_rgb(spectrum: list[tuple[float, float]] | float, emission: bool = False) -> RGB:
    """Linear sRGB of a spectrum, as Mitsuba 3's RGB variants turn a ``<spectrum>`` into a colour.

    A sampled spectrum is linear between its samples and zero outside them, integrated against the CIE 1931
    curves. A **reflectance** (``emission=False``) is white-balanced so that a flat spectrum of value v, and a
    uniform one, give (v, v, v). An **emission** spectrum is absolute: a flat or uniform one of value v gives
    ``v * EQUAL_ENERGY_RGB`` = v * (1.20, 0.95, 0.91), which is what Mitsuba 3.9.1 renders. Negative
    (out-of-gamut) components are clamped to zero, as Mitsuba does.
    Measured against Mitsuba 3.9.1: within 0.013 for reflectances and 0.013 for emission on test spectra.
    """
    if isinstance(spectrum, (int, float)):
        v = float(spectrum)
        rgb = np.multiply(v, EQUAL_ENERGY_RGB) if emission else np.array([v, v, v])
    else:
        w = np.array([p[0] for p in spectrum])
        v = np.array([p[1] for p in spectrum])
        samples = np.interp(_LAMBDA, w, v, left=0.0, right=0.0)
        if emission:
            rgb = XYZ_TO_LINEAR_SRGB @ (samples @ _CMF) / _Y_INTEGRAL
        else:
            rgb = (XYZ_TO_LINEAR_SRGB @ (samples @ _DAYLIGHT_CMF)) / _DAYLIGHT_WHITE
    return tuple(float(max(c, 0.0)) for c in rgb)  # type: ignore[return-value]


def conductor_f0(eta: RGB, k: RGB) -> RGB:
    """Reflectance at normal incidence of a conductor with complex index ``eta + i k`` (per channel)."""
    return tuple(((n - 1) ** 2 + kk * kk) / ((n + 1) ** 2 + kk * kk) for n, kk in zip(eta, k))  # type: ignore[return-value]


# Mitsuba 3.9.1's named conductors as its RGB variants use them: the complex index (eta, k) its measured
# spectra reduce to (read from Mitsuba's own `conductor` plugin, `mi.traverse`), so an imported metal has
# Mitsuba's Fresnel curve at every angle. (AlSb is left out: Mitsuba clamps its red eta to 0.)
MITSUBA_CONDUCTOR_IORS: dict[str, tuple[RGB, RGB]] = {
    "a-C": ((2.944, 2.227, 1.968), (0.8875, 0.7993, 0.8153)),
    "Ag": ((0.1553, 0.1167, 0.1384), (4.828, 3.122, 2.147)),
    "Al": ((1.658, 0.8804, 0.5212), (9.224, 6.27, 4.837)),
    "AlAs": ((3.605, 3.233, 2.216), (0.0006794, 0, 0.007513)),
    "AlAs_palik": ((3.605, 3.233, 2.216), (0.0006794, 0, 0.007513)),
    "Au": ((0.143, 0.3753, 1.442), (3.983, 2.386, 1.603)),
    "Be": ((4.185, 3.185, 2.784), (3.835, 3.01, 2.869)),
    "Cr": ((4.37, 2.917, 1.655), (5.207, 4.231, 3.755)),
    "CsI": ((2.145, 1.702, 1.662), (0, 0, 0)),
    "Cu": ((0.201, 0.9237, 1.102), (3.913, 2.453, 2.142)),
    "Cu2O": ((3.552, 2.95, 2.752), (0.1142, 0.1939, 0.6061)),
    "CuO": ((3.248, 2.448, 2.21), (0.5211, 0.57, 0.7222)),
    "d-C": ((2.709, 2.319, 2.229), (0, 0, 0)),
    "Hg": ((2.399, 1.44, 0.9096), (6.328, 4.372, 3.422)),
    "HgTe": ((4.779, 3.231, 2.66), (1.632, 1.581, 1.729)),
    "Ir": ((3.086, 2.082, 1.618), (5.592, 4.067, 3.267)),
    "K": ((0.06404, 0.04641, 0.03818), (2.104, 1.349, 0.9131)),
    "Li": ((0.2658, 0.1956, 0.2209), (3.54, 2.311, 1.669)),
    "MgO": ((2.09, 1.651, 1.595), (4.333e-12, 0, 2.499e-11)),
    "Mo": ((4.484, 3.525, 2.776), (4.111, 3.421, 3.151)),
    "Na_palik": ((0.06027, 0.05614, 0.06199), (3.179, 2.112, 1.579)),
    "Nb": ((3.42, 2.79, 2.396), (3.441, 2.738, 2.58)),
    "Ni_palik": ((2.367, 1.663, 1.467), (4.499, 3.05, 2.345)),
    "Rh": ((2.586, 1.86, 1.554), (6.782, 4.703, 3.976)),
    "Se": ((4.058, 2.843, 2.821), (0.754, 0.6384, 0.5218)),
    "SiC": ((3.172, 2.526, 2.479), (7.538e-07, 0, 1.019e-05)),
    "SnTe": ((4.524, 1.982, 1.282), (0, 0, 0)),
    "Ta": ((2.063, 2.393, 2.628), (2.408, 1.741, 1.947)),
    "Te": ((7.39, 4.482, 2.637), (3.256, 3.527, 3.292)),
    "ThF4": ((1.831, 1.442, 1.388), (0, 0, 0)),
    "TiC": ((3.701, 2.837, 2.582), (3.266, 2.352, 2.173)),
    "TiN": ((1.648, 1.151, 1.38), (3.368, 1.943, 1.102)),
    "TiO2": ((3.457, 2.802, 2.905), (0.0001053, 0, 0.0006529)),
    "VC": ((3.658, 2.753, 2.533), (3.068, 2.199, 1.963)),
    "V_palik": ((4.278, 3.513, 2.761), (3.491, 2.889, 3.112)),
    "VN": ((2.866, 2.119, 1.94), (3.032, 2.056, 1.616)),
    "W": ((4.371, 3.3, 2.998), (3.501, 2.605, 2.273)),
}

# Normal-incidence reflectance (linear sRGB) of Mitsuba's named conductors, for the interim conductor
# approximation. Values from measured indices of refraction (refractiveindex.info) at ~630/532/465 nm.
CONDUCTOR_F0: dict[str, RGB] = {
    "none": (1.0, 1.0, 1.0),  # Mitsuba's default: a perfect mirror
    "Ag": (0.972, 0.960, 0.915),
    "Al": (0.913, 0.922, 0.924),
    "Au": (1.000, 0.766, 0.336),
    "Cr": (0.550, 0.556, 0.554),
    "Cu": (0.955, 0.638, 0.538),
    "CuZn": (0.910, 0.780, 0.470),
    "Fe": (0.562, 0.565, 0.578),
    "Hg": (0.781, 0.779, 0.779),
    "Ni": (0.660, 0.609, 0.526),
    "Pt": (0.673, 0.637, 0.585),
    "Ti": (0.542, 0.497, 0.449),
    "W": (0.510, 0.500, 0.470),
    "Zn": (0.664, 0.824, 0.850),
}
