"""Paired runs (docs/notes/preview-overhead.md), without and with --preview while one headless Chromium keeps the page open.
Per run: wall seconds, the fppm process's CPU seconds, and (with the page) the CPU seconds all
Chromium processes used during the run. Usage: python3 cpu_pairs.py FPPM PASSES PAIRS"""
import os, subprocess, sys, time, glob, urllib.request, tempfile

fppm, passes, pairs = sys.argv[1], sys.argv[2], int(sys.argv[3])
tick = os.sysconf("SC_CLK_TCK")
d = tempfile.mkdtemp()
base = [fppm, "--width", "512", "--height", "512", "--passes", passes, "-q"]

def chromium_cpu():
    total = 0
    for stat in glob.glob("/proc/[0-9]*/stat"):
        try:
            text = open(stat).read()
        except OSError:
            continue
        name = text[text.index("(") + 1:text.rindex(")")]
        if name.startswith("chromium") or name.startswith("chrome"):
            fields = text[text.rindex(")") + 2:].split()
            total += int(fields[11]) + int(fields[12])  # utime, stime
    return total / tick

def run(args):
    start = time.monotonic()
    p = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(p.pid, 0)
    return time.monotonic() - start, usage.ru_utime + usage.ru_stime

def wait_server():
    while True:
        try:
            urllib.request.urlopen("http://127.0.0.1:8799/status", timeout=1).read()
            return
        except Exception:
            time.sleep(0.1)

# Start the browser on a short render; the page re-attaches to each later render.
warm = subprocess.Popen(base[:6] + ["10", "-q", "-o", f"{d}/w.exr", "--preview", "127.0.0.1:8799"],
                        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
wait_server()
chrome = subprocess.Popen(["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
    "--no-first-run", "--disable-background-networking", "--disable-component-update", "--disable-sync",
    f"--user-data-dir={d}/profile", "--remote-debugging-port=0", "http://127.0.0.1:8799/"],
    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
warm.wait()
time.sleep(3)
rows = []
for i in range(pairs):
    wall_b, cpu_b = run(base + ["-o", f"{d}/b.exr"])
    c0 = chromium_cpu()
    seen = [0]
    stop = [False]
    def watch():
        import json
        while not stop[0]:
            try:
                seen[0] = max(seen[0], json.load(urllib.request.urlopen("http://127.0.0.1:8799/status", timeout=1))["image"])
            except Exception:
                pass
            time.sleep(1)
    import threading
    t = threading.Thread(target=watch); t.start()
    wall_a, cpu_a = run(base + ["-o", f"{d}/a.exr", "--preview", "127.0.0.1:8799"])
    stop[0] = True; t.join()
    browser = chromium_cpu() - c0
    load = os.getloadavg()[0]
    print(f"pair {i+1}: wall {wall_a:.2f}/{wall_b:.2f} = {wall_a/wall_b:.4f}; fppm cpu {cpu_a:.2f}/{cpu_b:.2f} = {cpu_a/cpu_b:.4f}; "
          f"chromium cpu during the run {browser:.2f} s for {seen[0]} images; (fppm+chromium)/fppm = {(cpu_a+browser)/cpu_b:.4f}; load {load:.2f}", flush=True)
chrome.terminate()
chrome.wait()
