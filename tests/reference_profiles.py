"""Pure-numpy references of the self-affine profile and surface syntheses.

Implement the algorithms documented in the headers of ``src/profiles/self_affine.f90``
(module ``lc_profiles_self_affine``) and ``src/profiles/surface.f90`` (module
``lc_profiles_surface``), so that tests can check that the Fortran library and Python
produce the same heights to roundoff. Change both together.
"""

from __future__ import annotations

import numpy as np

_GAMMA = np.uint64(0x9E3779B97F4A7C15)
_MIX1 = np.uint64(0xBF58476D1CE4E5B9)
_MIX2 = np.uint64(0x94D049BB133111EB)


def splitmix64(seed: int, m: np.ndarray) -> np.ndarray:
    """Return the m-th SplitMix64 outputs (m = 1, 2, ...) for ``seed`` as uint64.

    Parameters
    ----------
    seed : int
        Seed, 0 <= seed < 2**64.
    m : array_like of int
        Output indices, 1 for the first output.

    Returns
    -------
    numpy.ndarray of uint64
        ``state_m = seed + m*0x9E3779B97F4A7C15 mod 2**64`` passed through the
        SplitMix64 mixing function; uint64 arithmetic wraps mod 2**64.
    """
    m = np.asarray(m, dtype=np.uint64)
    with np.errstate(over="ignore"):
        z = np.uint64(seed) + m * _GAMMA
        z = (z ^ (z >> np.uint64(30))) * _MIX1
        z = (z ^ (z >> np.uint64(27))) * _MIX2
    return z ^ (z >> np.uint64(31))


def splitmix64_uniform(seed: int, m: np.ndarray) -> np.ndarray:
    """Return the m-th SplitMix64 outputs mapped to [0, 1): ``(z >> 11) * 2**-53``."""
    return (splitmix64(seed, m) >> np.uint64(11)).astype(np.float64) * 2.0**-53


def self_affine_reference(
    n: int,
    period: float,
    hurst: float,
    seed: int,
    rolloff_wavelength: float | None = None,
    short_wavelength: float | None = None,
    rms_gradient: float | None = None,
    rms_height: float | None = None,
) -> np.ndarray:
    """Return the heights of a random self-affine line profile.

    Parameters
    ----------
    n : int
        Grid points per period; x_j = j*period/n, j = 0..n-1.
    period : float
        Period lambda (length unit L).
    hurst : float
        Hurst exponent H, 0 < H < 1; the spectrum is C(q) ~ q**(-1-2H).
    seed : int
        SplitMix64 seed, >= 0.
    rolloff_wavelength : float, optional
        Roll-off wavelength (L); default: the period.
    short_wavelength : float, optional
        Shortest wavelength (L); default: period/128.
    rms_gradient, rms_height : float, optional
        Scale target; give exactly one.

    Returns
    -------
    numpy.ndarray
        The n heights (L), zero mean.
    """
    if (rms_gradient is None) == (rms_height is None):
        raise ValueError("give exactly one of rms_gradient and rms_height")
    if rolloff_wavelength is None:
        rolloff_wavelength = period
    if short_wavelength is None:
        short_wavelength = period / 128
    m_max = (n - 1) // 2
    # Python's round() rounds half to even; Fortran's nint rounds half away from zero.
    m_r = int(np.floor(period / rolloff_wavelength + 0.5))
    m_s = min(int(np.floor(period / short_wavelength + 0.5)), m_max)
    if m_r > m_s:
        raise ValueError("roll-off mode above the shortest mode")

    m = np.arange(1, m_max + 1)
    q = 2 * np.pi * m / period
    amplitude = np.where(m < m_r, 1.0, (m / m_r) ** (-0.5 * (1 + 2 * hurst)))
    amplitude[m > m_s] = 0.0
    if rms_gradient is not None:
        scale = rms_gradient / np.sqrt(np.sum((q * amplitude) ** 2) / 2)
    else:
        scale = rms_height / np.sqrt(np.sum(amplitude**2) / 2)

    phase = 2 * np.pi * splitmix64_uniform(seed, m)
    spectrum = np.zeros(n // 2 + 1, dtype=np.complex128)
    spectrum[1 : m_max + 1] = scale * amplitude / 2 * np.exp(1j * phase)
    # irfft divides by n; the Fortran c2r transform does not.
    return np.fft.irfft(spectrum, n) * n


def surface_mode_index(mx: np.ndarray, my: np.ndarray) -> np.ndarray:
    """Return the SplitMix64 output index of the phase of mode (mx, my), mx >= 0.

    The Cantor pairing ``(mx + k)(mx + k + 1)/2 + k + 1`` of mx with my folded onto
    ``k = 2 my`` (my >= 0) or ``-2 my - 1`` (my < 0), as uint64.
    """
    mx = np.asarray(mx, dtype=np.int64)
    my = np.asarray(my, dtype=np.int64)
    k = np.where(my >= 0, 2 * my, -2 * my - 1)
    s = mx + k
    return (s * (s + 1) // 2 + k + 1).astype(np.uint64)


def self_affine_surface_reference(
    nx: int,
    ny: int,
    lx: float,
    ly: float,
    hurst: float,
    seed: int,
    rolloff_wavelength: float | None = None,
    short_wavelength: float | None = None,
    rms_gradient: float | None = None,
    rms_height: float | None = None,
) -> np.ndarray:
    """Return the heights of a random isotropic self-affine surface.

    Parameters
    ----------
    nx, ny : int
        Grid points; x = ix*lx/nx, y = iy*ly/ny.
    lx, ly : float
        Periods (length unit L).
    hurst : float
        Hurst exponent H, 0 < H < 1; the spectrum is C(q) ~ |q|**(-2-2H).
    seed : int
        SplitMix64 seed, >= 0.
    rolloff_wavelength : float, optional
        Roll-off wavelength (L); default: max(lx, ly).
    short_wavelength : float, optional
        Shortest wavelength (L); default: min(lx, ly)/128.
    rms_gradient, rms_height : float, optional
        Scale target; give exactly one.

    Returns
    -------
    numpy.ndarray
        ``(ny, nx)`` heights (L), zero mean.

    Notes
    -----
    The coefficients are placed on the full (ny, nx) spectrum, each representative mode
    with its conjugate at -q, and transformed by a complex inverse FFT: an independent
    check of the Fortran code's half-spectrum (c2r) filling. The imaginary part of the
    result is roundoff.
    """
    if (rms_gradient is None) == (rms_height is None):
        raise ValueError("give exactly one of rms_gradient and rms_height")
    rolloff = max(lx, ly) if rolloff_wavelength is None else rolloff_wavelength
    short = min(lx, ly) / 128 if short_wavelength is None else short_wavelength
    mx_max, my_max = (nx - 1) // 2, (ny - 1) // 2
    kappa_r2 = (1.0 / rolloff) ** 2
    kappa_s2 = min(1.0 / short, mx_max / lx, my_max / ly) ** 2
    if kappa_r2 > kappa_s2:
        raise ValueError("roll-off wavelength shorter than the shortest wavelength kept")

    my, mx = np.meshgrid(np.arange(-my_max, my_max + 1), np.arange(0, mx_max + 1), indexing="ij")
    representative = (mx > 0) | (my > 0)
    mx, my = mx[representative], my[representative]
    kappa2 = (mx / lx) ** 2 + (my / ly) ** 2
    kept = kappa2 <= kappa_s2 * (1 + 1e-9)
    mx, my, kappa2 = mx[kept], my[kept], kappa2[kept]
    amplitude = (np.maximum(kappa2, kappa_r2) / kappa_r2) ** (-0.5 * (1 + hurst))
    if rms_gradient is not None:
        scale = rms_gradient / np.sqrt((2 * np.pi) ** 2 * np.sum(kappa2 * amplitude**2) / 2)
    else:
        scale = rms_height / np.sqrt(np.sum(amplitude**2) / 2)

    phase = 2 * np.pi * splitmix64_uniform(seed, surface_mode_index(mx, my))
    coefficient = scale * amplitude / 2 * np.exp(1j * phase)
    spectrum = np.zeros((ny, nx), dtype=np.complex128)
    spectrum[my % ny, mx % nx] = coefficient
    spectrum[-my % ny, -mx % nx] = np.conj(coefficient)
    # ifft2 divides by nx*ny; the sum f(x) = sum_q f^(q) exp(i q.x) does not.
    return np.fft.ifft2(spectrum).real * (nx * ny)
