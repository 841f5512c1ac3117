#!/usr/bin/env python3
"""The README's commands as written: every ```bash block of README.md, command by command, from a
folder that holds the repository's build/ and examples/ (so their outputs stay out of the
repository), under an X server of its own for the window.

Commands that run until stopped (serve, edge, nats-server, a --window) start in the background,
as in a terminal of their own, and the next command waits for their port (or, for the window, its
first frames); a later server on the same port replaces the earlier one, and everything is
stopped at the end. Left out, with the reason printed: scripts/dev.sh (the
test command itself, and the demo, which CI runs as `probecast demo` in its own tests) and the
Python block (CI's `scripts/dev.sh python` installs and tests the same module).

Usage: readme_commands.py REPOSITORY WORK_DIR
"""
import os
import random
import re
import shutil
import signal
import socket
import subprocess
import sys
import time

repo, work = (os.path.abspath(p) for p in sys.argv[1:3])
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
for name in ("build", "examples"):
    os.symlink(os.path.join(repo, name), os.path.join(work, name))

LONG_RUNNING = re.compile(r"^(build/probecast (serve|edge)\b|nats-server\b)|--window\b")
LEFT_OUT = {"scripts/dev.sh": "the test and demo commands (CI runs them)",
            ".venv": "the Python block (CI's scripts/dev.sh python does the same)",
            "python3 -m venv": "the Python block (CI's scripts/dev.sh python does the same)"}


def fail(message):
    print("FAILED: " + message)
    sys.exit(1)


def blocks(text):
    """Each ```bash block as a list of commands (continuation lines joined, comments dropped)."""
    for body in re.findall(r"```bash\n(.*?)```", text, re.S):
        commands, current = [], ""
        for line in body.splitlines():
            line = line.split(" # ")[0].rstrip() if not line.lstrip().startswith("#") else ""
            if not line and not current:
                continue
            current += line.rstrip("\\").rstrip() + " " if line.endswith("\\") else line
            if not line.endswith("\\"):
                commands.append(current.strip())
                current = ""
        yield [c for c in commands if c]


def port_of(command):
    m = re.search(r"--listen \S*:(\d+)", command) or re.search(r"\s-p (\d+)", command)
    return int(m.group(1)) if m else None


def wait_port(port, process, what, log, seconds=60):
    end = time.time() + seconds
    while time.time() < end:
        if process.poll() is not None:
            fail(f"{what}: stopped ({process.returncode}) before listening on port {port}:\n{open(log).read()[-2000:]}")
        with socket.socket() as s:
            if s.connect_ex(("127.0.0.1", port)) == 0:
                return
        time.sleep(0.2)
    fail(f"{what}: nothing listens on port {port} after {seconds} s:\n{open(log).read()[-2000:]}")


def start_display():
    """An X server on a display number of its own (tests running beside this one start theirs)."""
    for _ in range(20):
        number = random.randint(100, 999)
        if os.path.exists(f"/tmp/.X{number}-lock"):
            continue
        xvfb = subprocess.Popen(["Xvfb", f":{number}", "-screen", "0", "1280x1024x24", "-nolisten", "tcp"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        end = time.time() + 10
        while xvfb.poll() is None and time.time() < end and not os.path.exists(f"/tmp/.X11-unix/X{number}"):
            time.sleep(0.1)
        if xvfb.poll() is None and os.path.exists(f"/tmp/.X11-unix/X{number}"):
            return xvfb, f":{number}"
        xvfb.kill()
    fail("no X server could be started (Xvfb)")


def stop(processes):
    for p, _, _ in processes:
        try:
            os.killpg(p.pid, signal.SIGTERM)
        except ProcessLookupError:
            pass
    for p, _, _ in processes:
        try:
            p.wait(timeout=20)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)


def start_background(command, env, log, background):
    """A command that runs until stopped; one already on its port (an earlier block's) gives way."""
    port = port_of(command)
    stop([b for b in background if port and port_of(b[1]) == port])
    background[:] = [b for b in background if not (port and port_of(b[1]) == port)]
    with open(log, "w") as out:
        p = subprocess.Popen(["bash", "-c", command], cwd=work, env=env, stdout=out, stderr=subprocess.STDOUT,
                             start_new_session=True)
    background.append((p, command, log))
    if port:
        wait_port(port, p, command, log)
    elif "--window" in command:
        end = time.time() + 90
        while "frames presented" not in open(log).read():
            if p.poll() is not None or time.time() > end:
                fail(f"the window presented no frames:\n{open(log).read()[-2000:]}")
            time.sleep(0.5)


def run_block(commands, env, index, background):
    for k, command in enumerate(commands):
        reason = next((why for key, why in LEFT_OUT.items() if key in command), None)
        if reason:
            print(f"left out: {command}  ({reason})")
            continue
        log = os.path.join(work, f"block{index}-{k}.log")
        print(f"$ {command}", flush=True)
        if LONG_RUNNING.search(command):
            start_background(command, env, log, background)
            continue
        with open(log, "w") as out:
            try:
                rc = subprocess.run(["bash", "-c", command], cwd=work, env=env, stdout=out, stderr=subprocess.STDOUT,
                                    timeout=150).returncode
            except subprocess.TimeoutExpired:
                fail(f"still running after 150 s: {command}\n{open(log).read()[-2000:]}")
        if rc != 0:
            fail(f"exit {rc}: {command}\n{open(log).read()[-3000:]}")
    for p, command, log in background:
        if p.poll() is not None:
            fail(f"stopped before its time ({p.returncode}): {command}\n{open(log).read()[-2000:]}")


xvfb, display = start_display()
try:
    env = dict(os.environ, DISPLAY=display, HOME=os.path.join(work, "home"))
    os.makedirs(env["HOME"])
    shutil.rmtree("/tmp/probecast-nats", ignore_errors=True)  # the README's bus keeps its store there
    readme = open(os.path.join(repo, "README.md")).read()
    background = []
    try:
        for index, commands in enumerate(blocks(readme)):
            run_block(commands, env, index, background)
    finally:
        stop(background)
finally:
    xvfb.terminate()

for path in ("out/view/quilt.png", "lg/looking_glass.png", "out/volume.pcpv", "token", "bus-token"):
    if not os.path.isfile(os.path.join(work, path)):
        fail(f"the README's commands did not write {path}")
window_logs = [f for f in os.listdir(work) if f.endswith(".log") and "frames presented" in open(os.path.join(work, f)).read()]
if not window_logs:
    fail("no window presented frames")
print("readme commands ok")
