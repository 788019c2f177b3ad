"""The text mesh formats' numbers read in compiled code (numba): an OBJ's statements and an ASCII PLY's body, one
pass over the bytes each, no Python per line. text_meshes.py turns what these return into meshes, and hands any
file outside the subset read here (a statement this reader does not know, a number it cannot parse) to trimesh.

Numbers. A decimal is read as an integer mantissa and a power of ten; when the mantissa is below 2^53 and the power
at most 22 in size, both are exact doubles and one division or product rounds correctly (Clinger 1990's fast
path), which covers what exporters write (six to nine decimals). A longer number (Python's 17-digit repr) is
left to an exact reader: numpy's strtod for a PLY's body, trimesh for an OBJ. Every number is then the double
the file's text means, as trimesh would read it.
"""

from __future__ import annotations

import numpy as np
from numba import njit

# Status codes shared with text_meshes.py.
READ = 0
OUTSIDE_SUBSET = 1  # a statement or token this reader does not handle: trimesh reads the file instead
LONG_NUMBERS = 2  # a number with more digits than rounds exactly here: numpy's strtod reads the numbers instead

# What _read_float makes of a token.
EXACT, INEXACT, NOT_A_NUMBER = 0, 1, 2
_EXACT_MANTISSA = 2 ** 53  # integers up to here are doubles exactly

POWERS_OF_TEN = np.array([10.0 ** k for k in range(23)])
_SPACE, _TAB, _CR, _NEWLINE = 32, 9, 13, 10


@njit(cache=True, inline="always")
def _is_blank(c):
    return c == _SPACE or c == _TAB or c == _CR


@njit(cache=True, inline="always")
def _skip_blanks(data, i, n):
    while i < n and _is_blank(data[i]):
        i += 1
    return i


@njit(cache=True, inline="always")
def _skip_line(data, i, n):
    while i < n and data[i] != _NEWLINE:
        i += 1
    return i + 1


@njit(cache=True)
def _beyond_exact(data, start, end):
    """Whether the digits in ``data[start:end]`` (a decimal point among them perhaps) make an integer beyond
    2^53, or one too long for 63 bits."""
    digits = 0
    mantissa = 0
    for k in range(start, end):
        if data[k] != 46:
            digits += 1
            if digits <= 18:
                mantissa = mantissa * 10 + (data[k] - 48)
    return digits > 18 or mantissa > _EXACT_MANTISSA


@njit(cache=True, inline="always")
def _read_float(data, i, n, powers):
    """The decimal number at ``data[i:]``: (value, index after it, EXACT, INEXACT or NOT_A_NUMBER)."""
    negative = False
    if i < n and (data[i] == 45 or data[i] == 43):  # - +
        negative = data[i] == 45
        i += 1
    start = i
    mantissa = 0
    while i < n and 48 <= data[i] <= 57:
        mantissa = mantissa * 10 + (data[i] - 48)
        i += 1
    scale = 0  # the power of ten the mantissa's last digit stands at
    if i < n and data[i] == 46:  # .
        i += 1
        fraction = i
        while i < n and 48 <= data[i] <= 57:
            mantissa = mantissa * 10 + (data[i] - 48)
            i += 1
        scale = fraction - i
    if i == start or (i == start + 1 and data[start] == 46):
        return 0.0, i, NOT_A_NUMBER
    # Perhaps more digits than a double holds exactly: counted where it is rare.
    beyond_exact = i - start > 15 and _beyond_exact(data, start, i)
    if i < n and (data[i] == 101 or data[i] == 69):  # e E
        exponent, i, ok = _read_int(data, i + 1, n)
        if not ok:
            return 0.0, i, NOT_A_NUMBER
        scale += exponent
    if beyond_exact:
        return 0.0, i, INEXACT
    if mantissa == 0:
        value = 0.0
    elif -22 <= scale <= 0:
        value = float(mantissa) / powers[-scale]
    elif 0 < scale <= 22:
        value = float(mantissa) * powers[scale]
    else:
        return 0.0, i, INEXACT
    return (-value if negative else value), i, EXACT


@njit(cache=True, inline="always")
def _read_int(data, i, n):
    """The integer at ``data[i:]``: (value, index after it, ok)."""
    negative = False
    if i < n and (data[i] == 45 or data[i] == 43):
        negative = data[i] == 45
        i += 1
    value = 0
    seen = False
    while i < n and 48 <= data[i] <= 57:
        seen = True
        if value < 10 ** 15:
            value = value * 10 + (data[i] - 48)
        i += 1
    return (-value if negative else value), i, seen


@njit(cache=True, inline="always")
def _ends_token(data, i, n):
    return i >= n or _is_blank(data[i]) or data[i] == _NEWLINE


# ---------------------------------------------------------------------------------------------------------
# OBJ
# ---------------------------------------------------------------------------------------------------------
# What a line states, from its first word.
_UNKNOWN, _POSITION, _UV, _NORMAL, _FACE, _USEMTL, _MTLLIB, _IGNORED = range(8)
# The kinds of named statements obj_parse returns the names of.
USEMTL, MTLLIB = 0, 1


@njit(cache=True, inline="always")
def _word_is(data, i, n, a, b, c, d, e, f):
    """Whether the six letters at ``data[i:]`` are a..f and end the word."""
    return i + 6 <= n and data[i] == a and data[i + 1] == b and data[i + 2] == c and data[i + 3] == d and \
        data[i + 4] == e and data[i + 5] == f and _ends_token(data, i + 6, n)


@njit(cache=True)
def _statement(data, i, n):
    """What the line at ``data[i:]`` (its first non-blank byte) states: v, vt, vn, f, usemtl and mtllib are read
    (the libraries' names for mesh_materials.py); o, g and s carry nothing the geometry needs (the normals are
    the file's or made smooth); anything else puts the file outside the subset."""
    c = data[i]
    if c == 118:  # v
        if _ends_token(data, i + 1, n):
            return _POSITION
        if i + 1 < n and data[i + 1] == 116 and _ends_token(data, i + 2, n):  # vt
            return _UV
        if i + 1 < n and data[i + 1] == 110 and _ends_token(data, i + 2, n):  # vn
            return _NORMAL
        return _UNKNOWN
    if c == 102 and _ends_token(data, i + 1, n):  # f
        return _FACE
    if (c == 111 or c == 103 or c == 115) and _ends_token(data, i + 1, n):  # o g s
        return _IGNORED
    if _word_is(data, i, n, 117, 115, 101, 109, 116, 108):  # usemtl
        return _USEMTL
    if _word_is(data, i, n, 109, 116, 108, 108, 105, 98):  # mtllib
        return _MTLLIB
    return _UNKNOWN


@njit(cache=True, inline="always")
def _next_statement(data, i, n):
    """The first byte of the next statement from ``data[i:]`` on, past blanks, empty lines and comments; n at
    the end."""
    while True:
        i = _skip_blanks(data, i, n)
        if i >= n or (data[i] != _NEWLINE and data[i] != 35):  # '#'
            return i
        i = i + 1 if data[i] == _NEWLINE else _skip_line(data, i, n)


@njit(cache=True)
def _continued(data, end, n):
    """Whether the line ending before ``end`` (the byte after its newline) ends in a backslash."""
    k = min(end, n) - 1
    if k >= 0 and data[k] == _NEWLINE:
        k -= 1
    if k >= 0 and data[k] == _CR:
        k -= 1
    return k >= 0 and data[k] == 92


@njit(cache=True)
def obj_counts(data):
    """Pass one: (status, byte offset of the first statement outside the subset, vertices, texture coordinates,
    normals, triangles (polygons fanned), usemtl and mtllib statements)."""
    n = data.shape[0]
    nv = nvt = nvn = ntri = nmtl = 0
    i = 0
    while True:
        i = _next_statement(data, i, n)
        if i >= n:
            break
        line = i
        statement = _statement(data, i, n)
        if statement == _POSITION:
            nv += 1
        elif statement == _UV:
            nvt += 1
        elif statement == _NORMAL:
            nvn += 1
        elif statement == _FACE:
            corners = 0
            i += 1
            while True:
                i = _skip_blanks(data, i, n)
                if i >= n or data[i] == _NEWLINE or data[i] == 35:
                    break
                corners += 1
                while not _ends_token(data, i, n):
                    i += 1
            if corners < 3:
                return OUTSIDE_SUBSET, line, 0, 0, 0, 0, 0
            ntri += corners - 2
        elif statement == _USEMTL or statement == _MTLLIB:
            nmtl += 1
        elif statement == _UNKNOWN:
            return OUTSIDE_SUBSET, line, 0, 0, 0, 0, 0
        i = _skip_line(data, i, n)
        if _continued(data, i, n):
            return OUTSIDE_SUBSET, line, 0, 0, 0, 0, 0
    return READ, -1, nv, nvt, nvn, ntri, nmtl


@njit(cache=True, inline="always")
def _obj_index(value, count):
    """An OBJ index (1-based, or negative: counted back from the last element so far) as 0-based; -1 where it
    names nothing written yet."""
    if value > 0:
        return value - 1 if value <= count else -1
    if value < 0:
        return count + value if count + value >= 0 else -1
    return -1


@njit(cache=True)
def obj_parse(data, nv, nvt, nvn, ntri, nmtl, powers):
    """Pass two: positions (nv, 3), texture coordinates (nvt, 2), normals (nvn, 3); each triangle's corners as
    position, texture-coordinate and normal indices (ntri, 3, 3; -1 where the corner has none); each triangle's
    usemtl statement (-1 before the first); each usemtl and mtllib statement's value as a byte span and its kind
    (nmtl, [start, end, USEMTL or MTLLIB]); and a status
    with the byte offset of the statement that put the file outside the subset."""
    positions = np.empty((nv, 3), np.float64)
    uvs = np.empty((nvt, 2), np.float64)
    normals = np.empty((nvn, 3), np.float64)
    corners = np.empty((ntri, 3, 3), np.int32)
    materials = np.empty(ntri, np.int32)
    names = np.empty((nmtl, 3), np.int64)
    n = data.shape[0]
    kv = kvt = kvn = kt = km = 0
    current = -1
    i = 0
    while True:
        i = _next_statement(data, i, n)
        if i >= n:
            break
        line = i
        statement = _statement(data, i, n)
        if statement == _POSITION or statement == _UV or statement == _NORMAL:
            kind = 0 if statement == _POSITION else (1 if statement == _UV else 2)
            i += 1 if kind == 0 else 2
            wanted = 2 if kind == 1 else 3
            x = y = z = 0.0
            for k in range(wanted):
                i = _skip_blanks(data, i, n)
                value, i, kind_of_number = _read_float(data, i, n, powers)
                if kind_of_number != EXACT or not _ends_token(data, i, n):  # trimesh's exact strtod
                    return OUTSIDE_SUBSET, line, positions, uvs, normals, corners, materials, names
                if k == 0:
                    x = value
                elif k == 1:
                    y = value
                else:
                    z = value
            i = _skip_blanks(data, i, n)
            if kind == 1 and i < n and data[i] != _NEWLINE and data[i] != 35:  # a third texture coordinate
                _, i, kind_of_number = _read_float(data, i, n, powers)
                if kind_of_number == NOT_A_NUMBER:
                    return OUTSIDE_SUBSET, line, positions, uvs, normals, corners, materials, names
                i = _skip_blanks(data, i, n)
            if i < n and data[i] != _NEWLINE and data[i] != 35:  # w, or vertex colours: trimesh's to read
                return OUTSIDE_SUBSET, line, positions, uvs, normals, corners, materials, names
            if kind == 0:
                positions[kv, 0], positions[kv, 1], positions[kv, 2] = x, y, z
                kv += 1
            elif kind == 1:
                uvs[kvt, 0], uvs[kvt, 1] = x, y
                kvt += 1
            else:
                normals[kvn, 0], normals[kvn, 1], normals[kvn, 2] = x, y, z
                kvn += 1
        elif statement == _FACE:
            i += 1
            count = 0
            first_p = first_t = first_n = last_p = last_t = last_n = -1
            while True:
                i = _skip_blanks(data, i, n)
                if i >= n or data[i] == _NEWLINE or data[i] == 35:
                    break
                value, i, ok = _read_int(data, i, n)
                p = _obj_index(value, kv)
                t = nrm = -1
                if not ok or p < 0:
                    return OUTSIDE_SUBSET, line, positions, uvs, normals, corners, materials, names
                if i < n and data[i] == 47:  # '/'
                    i += 1
                    if i < n and data[i] != 47:
                        value, i, ok = _read_int(data, i, n)
                        t = _obj_index(value, kvt)
                        if not ok or t < 0:
                            return OUTSIDE_SUBSET, line, positions, uvs, normals, corners, materials, names
                    if i < n and data[i] == 47:
                        i += 1
                        value, i, ok = _read_int(data, i, n)
                        nrm = _obj_index(value, kvn)
                        if not ok or nrm < 0:
                            return OUTSIDE_SUBSET, line, positions, uvs, normals, corners, materials, names
                if not _ends_token(data, i, n):
                    return OUTSIDE_SUBSET, line, positions, uvs, normals, corners, materials, names
                if count == 0:
                    first_p, first_t, first_n = p, t, nrm
                elif count >= 2:  # a fan around the first corner
                    corners[kt, 0, 0], corners[kt, 0, 1], corners[kt, 0, 2] = first_p, first_t, first_n
                    corners[kt, 1, 0], corners[kt, 1, 1], corners[kt, 1, 2] = last_p, last_t, last_n
                    corners[kt, 2, 0], corners[kt, 2, 1], corners[kt, 2, 2] = p, t, nrm
                    materials[kt] = current
                    kt += 1
                last_p, last_t, last_n = p, t, nrm
                count += 1
        elif statement == _USEMTL or statement == _MTLLIB:
            i = _skip_blanks(data, i + 6, n)
            start = i
            while i < n and data[i] != _NEWLINE:
                i += 1
            end = i
            while end > start and _is_blank(data[end - 1]):
                end -= 1
            names[km, 0], names[km, 1] = start, end
            names[km, 2] = USEMTL if statement == _USEMTL else MTLLIB
            if statement == _USEMTL:
                current = km
            km += 1
        i = _skip_line(data, i, n)
    return READ, -1, positions, uvs, normals, corners, materials, names


# ---------------------------------------------------------------------------------------------------------
# ASCII PLY
# ---------------------------------------------------------------------------------------------------------
@njit(cache=True)
def read_numbers(data, start, powers):
    """Every whitespace-separated number from ``data[start:]`` as a double: (status, numbers). The status is
    OUTSIDE_SUBSET where a token is not a decimal number (a comment or a word in the body: trimesh decides
    what it means), LONG_NUMBERS where some number has more digits than this reader rounds exactly."""
    n = data.shape[0]
    count = 0
    i = start
    while i < n:  # count the tokens first, to fill one array
        while i < n and (_is_blank(data[i]) or data[i] == _NEWLINE):
            i += 1
        if i < n:
            count += 1
        while i < n and not (_is_blank(data[i]) or data[i] == _NEWLINE):
            i += 1
    numbers = np.empty(count, np.float64)
    i = start
    status = READ
    for k in range(count):
        while _is_blank(data[i]) or data[i] == _NEWLINE:
            i += 1
        value, i, kind_of_number = _read_float(data, i, n, powers)
        if kind_of_number == NOT_A_NUMBER or not (i >= n or _is_blank(data[i]) or data[i] == _NEWLINE):
            return OUTSIDE_SUBSET, numbers
        if kind_of_number == INEXACT:
            status = LONG_NUMBERS  # read on, in case a token further on is no number at all
        numbers[k] = value
    return status, numbers


@njit(cache=True)
def fan_polygons(numbers, start, polygons):
    """PLY face rows (a corner count, then the corners) from ``numbers[start:]``, each polygon fanned around its
    first corner: (status, triangles, end of the rows)."""
    total = 0
    i = start
    for _ in range(polygons):
        if i >= numbers.shape[0]:
            return OUTSIDE_SUBSET, np.empty((0, 3), np.int64), i
        k = int(numbers[i])
        if k < 3 or k != numbers[i]:
            return OUTSIDE_SUBSET, np.empty((0, 3), np.int64), i
        total += k - 2
        i += k + 1
    triangles = np.empty((total, 3), np.int64)
    i = start
    t = 0
    for _ in range(polygons):
        k = int(numbers[i])
        for j in range(2, k):
            triangles[t, 0] = int(numbers[i + 1])
            triangles[t, 1] = int(numbers[i + j])
            triangles[t, 2] = int(numbers[i + j + 1])
            t += 1
        i += k + 1
    return READ, triangles, i
