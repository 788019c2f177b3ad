"""Direction numbers of the first four dimensions of the Sobol sequence, for glsl/rng.glsl.

From Joe & Kuo's table (new-joe-kuo-6.21201): dimension 1 is van der Corput's radical inverse; dimensions
2-4 use the primitive polynomials x+1, x^2+x+1 and x^3+x+1 with initial numbers (1), (1,3) and (1,3,1).
"""

from __future__ import annotations

# (degree s, polynomial coefficients a, initial direction numbers m) per dimension after the first.
_JOE_KUO = ((1, 0, (1,)), (2, 1, (1, 3)), (3, 1, (1, 3, 1)))
BITS = 32


def _directions(s: int, a: int, m: tuple[int, ...]) -> list[int]:
    v = [m[i] << (BITS - 1 - i) for i in range(s)]
    for i in range(s, BITS):
        value = v[i - s] ^ (v[i - s] >> s)
        for k in range(1, s):
            if (a >> (s - 1 - k)) & 1:
                value ^= v[i - k]
        v.append(value)
    return v


def sobol_directions() -> list[list[int]]:
    """4 lists of 32 direction numbers (as unsigned 32-bit integers)."""
    first = [1 << (BITS - 1 - i) for i in range(BITS)]
    return [first] + [_directions(*row) for row in _JOE_KUO]


def sobol_points(n: int) -> list[tuple[float, ...]]:
    """The first n points of the unscrambled 4-D sequence (a reference for tests)."""
    dirs = sobol_directions()
    points = []
    for index in range(n):
        coords = []
        for d in range(4):
            x = 0
            for bit in range(BITS):
                if (index >> bit) & 1:
                    x ^= dirs[d][bit]
            coords.append(x / 2**BITS)
        points.append(tuple(coords))
    return points


def glsl_array_literal() -> str:
    values = ", ".join(f"{v}u" for row in sobol_directions() for v in row)
    return f"uint[128]({values})"
