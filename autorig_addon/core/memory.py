"""The machine's memory: how much a job may still take, and refusing jobs
that would not fit, before they start.

A job that asks for more memory than the machine has does not fail cleanly:
it swaps for minutes, or the operating system kills Blender with the
artist's unsaved work. Jobs whose size is known up front (a voxel grid, a
dense weight table) estimate their bytes and call :func:`require_memory`,
which refuses with a message saying how much was needed and how much is
free.

The free memory is read without extra packages: ``MemAvailable`` from
``/proc/meminfo`` on Linux, ``GlobalMemoryStatusEx`` on Windows, and
``os.sysconf`` elsewhere (the available pages, else the installed memory).
"""

from __future__ import annotations

import ctypes
import os
import sys

from .errors import InputError

#: Where Linux says how much memory new work can take without swapping.
MEMINFO_PATH = "/proc/meminfo"
#: Share of the available memory a single job may plan to use: the rest is
#: left to Blender, the operating system and the estimate's error.
USABLE_MEMORY_SHARE = 0.8
#: Binary unit prefixes for :func:`format_bytes`, each 1024 times the previous.
BYTE_UNITS = ("bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB")


def available_memory_bytes() -> int | None:
    """Bytes of memory new work can take now, or None where the system does not say.

    Linux: ``MemAvailable`` of ``/proc/meminfo``; Windows: the available
    physical memory (``GlobalMemoryStatusEx``); other systems: available
    pages times the page size from ``os.sysconf``, else the installed memory.
    """
    try:
        with open(MEMINFO_PATH, encoding="ascii") as handle:
            for line in handle:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    if sys.platform == "win32":
        return _windows_available_bytes()
    for pages in ("SC_AVPHYS_PAGES", "SC_PHYS_PAGES"):
        try:
            count, size = os.sysconf(pages), os.sysconf("SC_PAGE_SIZE")
        except (AttributeError, ValueError, OSError):
            continue
        if count > 0 and size > 0:
            return int(count) * int(size)
    return None


def _windows_available_bytes() -> int | None:
    class MemoryStatus(ctypes.Structure):
        _fields_ = [("length", ctypes.c_ulong), ("load", ctypes.c_ulong), ("total_physical", ctypes.c_ulonglong),
                    ("available_physical", ctypes.c_ulonglong), ("total_page_file", ctypes.c_ulonglong),
                    ("available_page_file", ctypes.c_ulonglong), ("total_virtual", ctypes.c_ulonglong),
                    ("available_virtual", ctypes.c_ulonglong), ("available_extended_virtual", ctypes.c_ulonglong)]

    status = MemoryStatus()
    status.length = ctypes.sizeof(MemoryStatus)
    try:
        if ctypes.windll.kernel32.GlobalMemoryStatusEx(ctypes.byref(status)):
            return int(status.available_physical)
    except (AttributeError, OSError):
        pass
    return None


def format_bytes(count: float) -> str:
    """``count`` bytes in binary units with three significant digits.

    Examples
    --------
    >>> format_bytes(13 * 1024 ** 3), format_bytes(16e12), format_bytes(512), format_bytes(1023 * 1024)
    ('13 GiB', '14.6 TiB', '512 bytes', '1023 KiB')
    """
    value, unit = float(count), 0
    while value >= 1024.0 and unit < len(BYTE_UNITS) - 1:
        value /= 1024.0
        unit += 1
    return f"{value:.0f} {BYTE_UNITS[unit]}" if value >= 100.0 else f"{value:.3g} {BYTE_UNITS[unit]}"


def usable_memory_bytes() -> int | None:
    """The bytes one job may plan to use: :data:`USABLE_MEMORY_SHARE` of
    :func:`available_memory_bytes` (None where unknown)."""
    available = available_memory_bytes()
    return None if available is None else int(USABLE_MEMORY_SHARE * available)


def require_memory(needed_bytes: float, what: str, advice: str) -> None:
    """Raise :class:`InputError` when ``needed_bytes`` exceed
    :func:`usable_memory_bytes` (never where the free memory is unknown).

    Parameters
    ----------
    needed_bytes : float, the job's estimated peak
    what : str, the job, completing "... would need N" (e.g. "Skinning at resolution 1024")
    advice : str, what to do instead, a full sentence (e.g. "Use resolution 384 or less.")
    """
    available = available_memory_bytes()
    if available is not None and needed_bytes > USABLE_MEMORY_SHARE * available:
        raise InputError(
            f"{what} would need about {format_bytes(needed_bytes)} of memory, but only "
            f"{format_bytes(available)} is free. {advice}"
        )
