"""Run the reference Evolver and pick numbers out of its transcript."""
import re
import subprocess

_PROMPT = "Enter command: "


#: commands whose Hessian REF assembles wrongly with worker threads: with
#: ``-p1`` its matrix of a method quantity loses the terms between
#: different vertices (and, by file size and thread count, some of a
#: vertex's own block); run without ``-p`` (one thread, REF's default) its
#: matrix is the exact one (docs/differences.md, "REF's threaded Hessian")
_HESSIAN = re.compile(r"\b(hessian\w*|saddle|ritz|eigenprobe|lanczos)\b", re.I)


def reference_args(exe, datafile, commands):
    """REF's command line: ``-p1`` (one worker thread: bit-for-bit
    repeatable), but without worker threads when ``commands`` use a Hessian."""
    return [exe, datafile] if _HESSIAN.search(commands) else [exe, "-p1", datafile]


def run_reference(exe, datafile, commands, timeout=60, cwd=None):
    """Run ``evolver-nox-d -p1 datafile`` (without ``-p1`` for Hessian
    commands, :func:`reference_args`) with ``commands`` on stdin.

    Returns the list of output lines printed by the commands (the banner,
    prompts and echoed input removed).
    """
    text = commands if commands.endswith("\n") else commands + "\n"
    text += "q\nq\n"
    proc = subprocess.run(reference_args(exe, datafile, text), input=text, capture_output=True,
                          text=True, timeout=timeout, cwd=cwd, errors="replace")
    out = proc.stdout
    blocks = out.split(_PROMPT)[1:]
    lines = []
    for b in blocks:
        bl = b.split("\n")
        rest = bl[1:]                       # first line is the echo of the input
        for ln in rest:
            ln = re.sub(r"\x1b\[[0-9;]*[A-Za-z]", "", ln)
            if ln.startswith("more> ") or ln.startswith("Enter new datafile name"):
                continue
            lines.append(ln)
    while lines and not lines[-1].strip():
        lines.pop()
    return lines


def numbers(exe, datafile, exprs, cwd=None):
    """Evaluate expressions in the reference after loading: list of floats."""
    cmds = "".join(f'printf "RESULT %.17g\\n", {e}\n' for e in exprs)
    lines = run_reference(exe, datafile, cmds, cwd=cwd)
    vals = [float(l.split()[1]) for l in lines if l.startswith("RESULT")]
    if len(vals) != len(exprs):
        raise AssertionError("reference did not print every value:\n" + "\n".join(lines))
    return vals
