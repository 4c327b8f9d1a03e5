"""Helpers shared by nave's benchmark scripts (bench_pager_budget.py, bench_pager_scale.py, bench_reference.py).

Running nave under /usr/bin/time -v, telling a refused budget from a failure, reading the "nave:statistics"
metadata of a rendered EXR, parsing budgets as nave does, writing CSV and Markdown tables, loading pyplot.
Needs the Debian packages installed by bench/setup-bench.sh (python3-openimageio, python3-matplotlib, time).
"""

import csv
import json
import os
import re
import subprocess
import tempfile

TIME = "/usr/bin/time"
SETUP_HINT = "run bench/setup-bench.sh to install the benchmark packages"


class TimedRun:
    """One process run under /usr/bin/time -v: its exit code, its output and what time measured."""

    def __init__(self, returncode, output, peak_rss_bytes, elapsed_s, cpu_s):
        self.returncode = returncode
        self.output = output  # stdout and stderr of the command, interleaved
        self.peak_rss_bytes = peak_rss_bytes  # whole process, children included; None if time said nothing
        self.elapsed_s = elapsed_s
        self.cpu_s = cpu_s  # user + system

    @property
    def ok(self):
        return self.returncode == 0


def log_command(cmd, log):
    log.write("$ " + " ".join(cmd) + "\n")
    log.flush()


def run_logged(cmd, log):
    """Runs `cmd`, appends the command line and its output to `log`, returns the CompletedProcess."""
    log_command(cmd, log)
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    log.write(p.stdout)
    log.flush()
    return p


def parse_time_verbose(text):
    """The report of `/usr/bin/time -v` -> {'Maximum resident set size (kbytes)': '1234', ...}."""
    out = {}
    for line in text.splitlines():
        key, sep, value = line.strip().rpartition(": ")
        if sep:
            out[key] = value.strip()
    return out


def _elapsed_seconds(text):
    """'1:02:03.4' or '2:03.45' (time -v's wall clock) -> seconds."""
    seconds = 0.0
    for part in text.split(":"):
        seconds = seconds * 60 + float(part)
    return seconds


def run_timed(cmd, log):
    """Runs `cmd` under `/usr/bin/time -v` (its report goes to a file of its own, so that nave's output is
    not mixed with it) and returns a TimedRun. The command and its output are appended to `log`."""
    if not os.access(TIME, os.X_OK):
        raise SystemExit(f"{TIME} is missing: {SETUP_HINT}")
    with tempfile.NamedTemporaryFile("r", prefix="nave-bench-time-", suffix=".txt") as report:
        p = run_logged([TIME, "-v", "-o", report.name] + cmd, log)
        report.seek(0)
        measured = parse_time_verbose(report.read())
    log.write(f"peak RSS {measured.get('Maximum resident set size (kbytes)', '?')} KiB\n")
    rss_kb = measured.get("Maximum resident set size (kbytes)")
    elapsed = measured.get("Elapsed (wall clock) time (h:mm:ss or m:ss)")
    user = measured.get("User time (seconds)")
    system = measured.get("System time (seconds)")
    return TimedRun(
        returncode=p.returncode,
        output=p.stdout,
        peak_rss_bytes=int(rss_kb) * 1024 if rss_kb else None,
        elapsed_s=_elapsed_seconds(elapsed) if elapsed else None,
        cpu_s=round(float(user) + float(system), 2) if user and system else None,
    )


_LOG_LINE = re.compile(r"^nave (trace|debug|info|warning|error|critical): ")


def error_reason(output, returncode):
    """Why nave stopped: the first line of its error message ("nave: error: ..." without the prefix). For a
    process that printed none (a command-line error, a crash, a signal): how it ended, then its first error
    log line, else its first line that is not a log line, else its last line."""
    lines = [line.strip() for line in output.splitlines() if line.strip()]
    for line in lines:
        if line.startswith("nave: error: "):
            return line[len("nave: error: "):]
    how = f"killed by signal {-returncode}" if returncode < 0 else f"exit code {returncode}"
    logged = [line for line in lines if re.match(r"^nave (error|critical): ", line)]
    plain = [line for line in lines if not _LOG_LINE.match(line)]
    detail = (logged or plain or lines[-1:] or [None])[0]
    return f"{how}: {detail}" if detail else how


def run_status(returncode, reason):
    """'ok', 'refused' (nave turned the budget down before rendering: a resource-exhausted error such as
    '--memory ... is too small for this model') or 'failed' (anything else)."""
    if returncode == 0:
        return "ok"
    if reason.startswith("resource exhausted:") or "too small for this model" in reason:
        return "refused"
    return "failed"


def read_exr_attribute(path, name):
    """A string attribute of an image's header (e.g. "nave:statistics"), read with OpenImageIO."""
    try:
        import OpenImageIO as oiio
    except ImportError:
        raise SystemExit(f"python3-openimageio is missing (use /usr/bin/python3): {SETUP_HINT}")
    image = oiio.ImageInput.open(str(path))
    if image is None:
        raise ValueError(f"{path}: cannot open: {oiio.geterror()}")
    try:
        value = image.spec().getattribute(name)
    finally:
        image.close()
    if value is None:
        raise ValueError(f"{path}: no '{name}' attribute in the header")
    return str(value)


_NUMBER_WITH_UNIT = re.compile(r"^([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)(s)?$")


def parse_statistics(text):
    """nave's statistics line -> dict: 'wall=1.234s brick_loads=5 brick_budget=in-core' ->
    {'wall': 1.234, 'brick_loads': 5, 'brick_budget': 'in-core'}. Integers stay int, '1.5s' becomes seconds,
    anything else is kept as text; unknown keys are kept, items without '=' ignored."""
    out = {}
    for item in text.split():
        key, sep, value = item.partition("=")
        if not sep or not key:
            continue
        m = _NUMBER_WITH_UNIT.match(value)
        if not m:
            out[key] = value
        elif m.group(2) is None and re.fullmatch(r"[-+]?\d+", m.group(1)):
            out[key] = int(m.group(1))
        else:
            out[key] = float(m.group(1))
    return out


def read_statistics(exr_path):
    """The "nave:statistics" metadata of a rendered EXR, parsed."""
    return parse_statistics(read_exr_attribute(exr_path, "nave:statistics"))


_BYTE_UNITS = {"": 1, "K": 1 << 10, "M": 1 << 20, "G": 1 << 30, "T": 1 << 40}


def parse_byte_size(text):
    """'2G', '512M', '1.5GiB', '300MB', '123' -> bytes, as nave's --memory reads them (powers of 1024)."""
    m = re.fullmatch(r"\s*(\d+(?:\.\d*)?)\s*([KMGT]?)(?:i?B)?\s*", text, re.IGNORECASE)
    if not m:
        raise ValueError(f"'{text}' is not a size (forms: 123, 64K, 512M, 1.5G, 2GiB, 300MB)")
    return int(float(m.group(1)) * _BYTE_UNITS[m.group(2).upper()])


def write_csv(path, fields, rows):
    """Rows (dicts) to CSV with the given column order; a missing value is an empty cell."""
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=fields, restval="")
        writer.writeheader()
        writer.writerows(rows)


def markdown_table(headers, rows):
    """A Markdown table: `headers` the column titles, `rows` lists of cells (anything str() can print)."""
    lines = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
    for row in rows:
        lines.append("| " + " | ".join(str(c).replace("|", "\\|") for c in row) + " |")
    return "\n".join(lines)


def pyplot():
    """matplotlib.pyplot on the Agg backend (files only, no display), or None when matplotlib is missing."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return None
    return plt


def default_nave():
    """The release build's nave binary."""
    return "build/release/src/cli/nave"


# The abbey's camera spots (docs/abbey.md, "Camera spots"): eye, look-at, vertical field of view.
VIEWS = {
    "nave": ((4.0, 0.0, 1.7), (60.0, 0.0, 12.0), 65),
    "crossing_vault": ((62.5, -4.0, 1.7), (62.5, 0.5, 28.0), 90),
    "north_aisle": ((2.0, 10.0, 1.7), (50.0, 10.0, 6.0), 70),
    "choir": ((70.0, 3.0, 1.7), (92.0, 0.0, 9.0), 75),
}


def parse_views(text):
    """'nave,north_aisle' -> ['nave', 'north_aisle']; exits naming an unknown view."""
    views = [v.strip() for v in text.split(",") if v.strip()]
    for v in views:
        if v not in VIEWS:
            raise SystemExit(f"--views: unknown view '{v}' (known: {', '.join(VIEWS)})")
    return views


def config_for_view(base_text, view):
    """A config's text (configs/abbey.toml's) with its [camera] position, look_at and fov_deg set to `view`'s."""
    eye, at, fov = VIEWS[view]
    text = base_text
    for key, value in (("position", f"[{eye[0]}, {eye[1]}, {eye[2]}]"),
                       ("look_at", f"[{at[0]}, {at[1]}, {at[2]}]"), ("fov_deg", str(fov))):
        text, n = re.subn(rf"(?m)^{key}\s*=.*$", f"{key} = {value}", text, count=1)
        if n != 1:
            raise SystemExit(f"the config has no [camera] {key} to replace")
    return text


def compare(nave, a, b, reference, log):
    """`nave compare A B [--reference] --json` as a dict."""
    cmd = [nave, "compare", a, b, "--json"] + (["--reference"] if reference else [])
    p = run_logged(cmd, log)
    if p.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed: {p.stdout.strip()}")
    return json.loads(p.stdout.strip().splitlines()[-1])


def worst_region_ratio(result):
    """From `nave compare A REF --json`: the region whose mean luminance is furthest from the reference's,
    as A / reference."""
    worst = 1.0
    for a, ref in result["region_mean_luminance"]:
        if ref > 0 and abs(a / ref - 1) > abs(worst - 1):
            worst = a / ref
    return worst


def abbey_store_and_view(nave, out_dir, detail, store, config, view, log, levels=False):
    """The store to render (`store`, or the procedural abbey of `detail` generated into `out_dir` once, with
    levels of detail if `levels`) and a config for `view` written beside it from `config`: -> (store path,
    config path)."""
    store = store or os.path.join(out_dir, f"abbey{detail}{'-levels' if levels else ''}.nave")
    if not os.path.exists(store):
        p = run_logged([nave, "preprocess", "--generate", f"abbey:detail={detail}", "-q", "-o", store]
                       + (["--levels"] if levels else []), log)
        if p.returncode != 0:
            raise SystemExit(f"preprocess failed: see {log.name}")
    view_config = os.path.join(out_dir, f"{view}.toml")
    with open(config) as f:
        text = config_for_view(f.read(), view)
    with open(view_config, "w") as f:
        f.write(text)
    return store, view_config


def add_abbey_run_arguments(ap, out_dir):
    """The options of a bench that renders the procedural abbey (or --store) from one view: the nave binary,
    the output directory (default `out_dir`), the model, the config and view, the resolution and samples."""
    ap.add_argument("--nave", default=default_nave())
    ap.add_argument("--dir", default=out_dir)
    ap.add_argument("--detail", type=int, default=30)
    ap.add_argument("--levels", action="store_true",
                    help="the abbey preprocessed with levels of detail (rendered with them: --lod auto)")
    ap.add_argument("--store", default="")
    ap.add_argument("--config", default="configs/abbey.toml")
    ap.add_argument("--view", default="nave")
    ap.add_argument("--resolution", default="320x213")
    ap.add_argument("--spp", type=int, default=4)
