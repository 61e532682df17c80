"""What every section of the validation report uses: running the binaries, reading their CSV and
WAV output, saving figures and recording checks. A section gets one Context and returns markdown."""
import os
import shlex
import subprocess
import time
import wave

import matplotlib
matplotlib.use("Agg")  # no display in CI
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

plt.rcParams.update({"figure.dpi": 110, "savefig.dpi": 110, "axes.grid": True,
                     "grid.alpha": 0.3, "font.size": 9, "legend.fontsize": 8})


class Context:
    """One section's view of the run.

    sim, render: paths of hamiltone-sim and hamiltone-render; work: a scratch directory of the
    section's own (deleted afterwards); figures: where PNGs go (the report links them as
    figures/NAME); quick: the reduced run; source: the repository root; grids: the path of
    bench/hamiltone_validate_grids, or None where the benchmarks were not built."""

    def __init__(self, name, sim, render, work, figures, quick, source, grids=None):
        self.name, self.sim, self.render, self.grids = name, sim, render, grids
        self.work, self.figures, self.quick, self.source = work, figures, quick, source
        self.saved = []      # figure file names this section wrote
        self.skipped = []    # (figure name, reason) of figures that could not be made
        self.failures = []   # basic checks that failed: the driver exits non-zero in --quick
        self.commands = []   # every command run, as typed (paths shortened)

    def path(self, name):
        """A file in the section's scratch directory."""
        return os.path.join(self.work, name)

    def shown(self, args):
        """A command as a reader would type it from the repository root."""
        out = []
        for a in map(str, args):
            if a == self.sim:
                a = "build/release/sim/hamiltone-sim"
            elif a == self.render:
                a = "build/release/render/hamiltone-render"
            elif a == self.grids:
                a = "build/release/bench/hamiltone_validate_grids"
            elif a.startswith(self.work + os.sep):
                a = os.path.relpath(a, self.work)
            elif a.startswith(self.source + os.sep):
                a = os.path.relpath(a, self.source)
            out.append(a)
        return " ".join(shlex.quote(a) for a in out)

    def run(self, args, allow_fail=False):
        """Runs a command; returns (stdout, seconds). Raises on a non-zero exit unless allowed."""
        args = [str(a) for a in args]
        start = time.monotonic()
        done = subprocess.run(args, capture_output=True, text=True)
        seconds = time.monotonic() - start
        self.commands.append(self.shown(args))
        if done.returncode != 0 and not allow_fail:
            raise RuntimeError(f"{self.shown(args)} exited {done.returncode}: {done.stderr.strip()}")
        return done.stdout + done.stderr, seconds

    def sim_run(self, command, out, **flags):
        """hamiltone-sim COMMAND --flag value ... --out OUT; returns (columns, comment, stdout).
        Keyword flags use underscores for dashes: grid_factor=1.05 -> --grid-factor 1.05."""
        args = [self.sim, command]
        for key, value in flags.items():
            args += ["--" + key.replace("_", "-"), value]
        args += ["--out", out]
        text, _ = self.run(args)
        columns, comment = read_csv(out)
        return columns, comment, text

    def figure(self, fig, name, caption):
        """Saves `fig` as figures/NAME.png; returns the markdown that shows it."""
        file = name + ".png"
        fig.savefig(os.path.join(self.figures, file), bbox_inches="tight")
        plt.close(fig)
        self.saved.append(file)
        return f"![{caption}](figures/{file})\n\n*{caption}*\n"

    def skip(self, name, reason):
        """A figure that could not be made; the report says why, in place of it."""
        self.skipped.append((name + ".png", reason))
        return f"> **Figure `{name}.png` skipped:** {reason}\n"

    def check(self, ok, what):
        """A basic check: `what` says what was expected. Returns a markdown verdict."""
        if not ok:
            self.failures.append(what)
            return f"**FAILED: {what}.**"
        return f"Check passed: {what}."


def read_csv(path):
    """A hamiltone-sim CSV: '#' comment lines, a header, rows of numbers. Returns
    ({column: array}, {key: value of the comment's key=value pairs})."""
    comment = {}
    with open(path) as f:
        header = f.readline()
        while header.startswith("#"):
            for item in header[1:].split():
                if "=" in item:
                    key, value = item.split("=", 1)
                    comment[key] = value
            header = f.readline()
        names = header.strip().split(",")
        data = np.loadtxt(f, delimiter=",", ndmin=2)
    if data.size == 0:
        data = np.zeros((0, len(names)))
    return {n: data[:, i] for i, n in enumerate(names)}, comment


def read_wav(path):
    """A mono or stereo PCM WAV (16 or 24 bit) as (float samples summed to mono, sample rate)."""
    with wave.open(path, "rb") as w:
        channels, width, rate = w.getnchannels(), w.getsampwidth(), w.getframerate()
        raw = np.frombuffer(w.readframes(w.getnframes()), dtype=np.uint8)
    if width == 2:
        x = raw.view("<i2").astype(float) / 32768.0
    elif width == 3:
        b = raw.reshape(-1, 3).astype(np.int32)
        v = b[:, 0] | (b[:, 1] << 8) | (b[:, 2] << 16)
        x = np.where(v >= 1 << 23, v - (1 << 24), v).astype(float) / float(1 << 23)
    else:
        raise ValueError(f"{path}: {8 * width}-bit samples are not read here")
    return x.reshape(-1, channels).mean(axis=1), rate


def spectrum(x, rate, start, length, pad=4):
    """Magnitude spectrum of x[start : start + length] seconds, Hann window, zero-padded."""
    a, n = int(start * rate), int(length * rate)
    seg = x[a:a + n] * np.hanning(len(x[a:a + n]))
    size = pad * len(seg)
    return np.fft.rfftfreq(size, 1 / rate), np.abs(np.fft.rfft(seg, size))


def peak(freqs, mag, lo, hi):
    """The largest peak in [lo, hi], refined by a parabola through log magnitudes."""
    sel = np.nonzero((freqs >= lo) & (freqs <= hi))[0]
    i = sel[np.argmax(mag[sel])]
    a, b, c = np.log(mag[i - 1:i + 2] + 1e-300)
    shift = 0.5 * (a - c) / (a - 2 * b + c) if a - 2 * b + c != 0 else 0.0
    return freqs[i] + shift * (freqs[1] - freqs[0]), mag[i]


def pitch_track(x, rate, lo, hi, frame=0.2, hop=0.025, stop=None):
    """The strongest peak in [lo, hi] Hz over time: Hann frames of `frame` s every `hop` s,
    starting before `stop` s (default: every frame that fits in x), zero-padded ×16, parabolic
    peak. Returns (frame centres, Hz)."""
    fits = (len(x) - int(frame * rate)) / rate + 1e-9
    times = np.arange(0.0, fits if stop is None else min(stop, fits), hop)
    pitch = [peak(*spectrum(x, rate, t, frame, pad=16), lo, hi)[0] for t in times]
    return times + frame / 2, np.array(pitch)


def relative_deviation(energy):
    """(51): (H^{n+1/2} - H^{1/2}) / H^{1/2}."""
    return (energy - energy[0]) / energy[0]


def fmt(x, digits=2):
    """A number for prose: 3 significant digits in scientific notation where useful."""
    if x == 0 or not np.isfinite(x):
        return str(x)
    if 1e-3 <= abs(x) < 1e4:
        return f"{x:.{digits + 1}g}"
    return f"{x:.{digits}e}"


def code(command):
    """A command in a markdown code block."""
    return f"\n```\n{command}\n```\n"


def cpu_model():
    """The CPU's model name from /proc/cpuinfo ('unknown CPU' elsewhere)."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown CPU"


def energy_figure(t, deviation, output, output_label, title):
    """BDZ Figs. 6 and 11: the relative energy deviation (51) above the output, t in seconds."""
    fig, (a, b) = plt.subplots(2, 1, figsize=(9, 4.6), sharex=True)
    a.plot(t * 1e3, deviation, lw=0.5, color="tab:green")
    a.set_ylabel("(H − H⁰)/H⁰ (51)")
    a.set_title(title)
    b.plot(t * 1e3, output * 1e3, lw=0.8, color="black")
    b.set_ylabel(output_label)
    b.set_xlabel("t (ms)")
    fig.tight_layout()
    return fig
