"""Peak resident memory of a call, for the benchmarks (Linux /proc only)."""


def _status_mib(field: str) -> float:
    with open("/proc/self/status") as status:
        return next(int(line.split()[1]) for line in status if line.startswith(field)) / 1024.0


def peak_rss_added(function) -> float:
    """MiB of resident memory above the starting level at the peak of ``function()``."""
    with open("/proc/self/clear_refs", "w") as clear:
        clear.write("5")  # resets VmHWM to the current RSS
    start = _status_mib("VmRSS:")
    function()
    return _status_mib("VmHWM:") - start
