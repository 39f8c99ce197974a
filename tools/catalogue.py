#!/usr/bin/env python3
"""The reliability catalogue: adversarial cases run against the `stereolab` binary, each
checked for the rules of docs/reliability.md.

    cargo build && python3 tools/catalogue.py [--bin target/debug/stereolab] [--quick]

Every case runs one command and checks, whatever its outcome:
  * it ends by itself (a time limit per case) with exit code 0, 1, 2 or 3, never a signal or
    Rust's panic code 101, and stderr says no "panicked";
  * stderr holds no Rust or serde words (`invalid type`, `untagged`, `expected f32`…) and no raw
    control character but newline and tab (escape injection);
  * the output folder holds no temporary file (`.NAME.tmp-…`) afterwards;
  * a failed run leaves every output it was given as it was (seeded files are compared);
  * a successful run's PNG outputs decode (the PNG signature and IEND chunk are there).
Some classes add their own check (the exit code of a signal, the words of a message).

It prints one line per failing case and a count per class; exit code 1 when any case fails.
Standard library only.
"""

import argparse
import itertools
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCENES = ROOT / "assets" / "scenes"
RUST_WORDS = ["untagged", "SeparationSpec", "invalid type", "wanted string", "expected struct",
              "expected f32", "expected u32", "expected usize", "expected a sequence",
              "panicked", "RUST_BACKTRACE"]
CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f]")

BASE_SCENE = """outputs = ["left", "right", "anaglyph_dubois"]
[image]
width = 32
height = 24
[camera]
eye = [0, 0, 5]
target = [0, 0, 0]
near = 1
far = 10
[stereo]
eye_separation = 0.2
zero_parallax = 5
[[mesh]]
kind = "cube"
"""

HOSTILE_VALUES = ["0", "-1", "1e30", "-1e30", "1e-45", "nan", "inf", "-inf", "4294967295",
                  "18446744073709551615", "64.5", "\"\"", "\"auto\"", "\"fit\"", "[1, 2]",
                  "[1,0,0", "{a = 1}", "true", "abc", "\"\x1b[31mred\"", "\"" + "x" * 5000 + "\"",
                  "[0, 0, 0]", "[]", "2", ""]
SET_KEYS = ["image.width", "image.height", "camera.eye", "camera.target", "camera.near",
            "camera.far", "camera.fov_y", "stereo.eye_separation", "stereo.zero_parallax",
            "stereo.mode", "mesh.0.kind", "mesh.0.color", "mesh.0.scale", "mesh.0.detail",
            "mesh.0.count", "mesh.0.rotate", "layout.blank_interval", "light.shininess",
            "sirds.dpi", "sirds.oversample", "chromadepth.d1", "raster.depth", "outputs",
            "nosuch.table", "mesh.3.color", "camera.fov_y.x"]

OBJ_LINES = ["v 1 2 3 4 5 6 7", "f 1/2/3/4 2 3", "f 1 2", "f 0 1 2", "f -9 1 2", "v nan 0 0",
             "v 1e39 0 0", "v 3.1+e2 0 0", "vn 1 1", "f 1// 2// 3//", "usemtl", "mtllib nosuch.mtl",
             "f 1 2 99999999999999999999", "\x1b[2J", "v 1 2", "o \x07bell"]


class Catalogue:
    def __init__(self, binary, work, quick):
        self.bin = str(binary)
        self.work = Path(work)
        self.quick = quick
        self.counts = {}
        self.failures = []
        self.n = 0

    def folder(self):
        self.n += 1
        d = self.work / f"case{self.n}"
        d.mkdir(parents=True)
        return d

    def record(self, cls, name, problems):
        ok, bad = self.counts.get(cls, (0, 0))
        if problems:
            self.counts[cls] = (ok, bad + 1)
            self.failures.append(f"{cls}: {name}: {'; '.join(problems)}")
        else:
            self.counts[cls] = (ok + 1, bad)

    def run(self, cls, name, args, out_dir=None, seeded=None, timeout=120, env=None,
            expect_codes=(0, 1, 2, 3), check=None, preexec=None):
        """Runs `stereolab ARGS`; `seeded` maps paths to bytes written before the run, which
        a failed run must leave as they were."""
        seeded = seeded or {}
        for p, b in seeded.items():
            p.parent.mkdir(parents=True, exist_ok=True)
            p.write_bytes(b)
        problems = []
        try:
            r = subprocess.run([self.bin, *args], capture_output=True, timeout=timeout,
                               env={**os.environ, **(env or {})}, preexec_fn=preexec)
        except subprocess.TimeoutExpired:
            self.record(cls, name, [f"no answer within {timeout} s"])
            return None
        err = r.stderr.decode("utf-8", "replace")
        if r.returncode not in expect_codes:
            problems.append(f"exit code {r.returncode}")
        for w in RUST_WORDS:
            if w in err:
                problems.append(f"stderr says {w!r}")
        if CONTROL.search(err):
            problems.append("a raw control character on stderr")
        for d in [out_dir] if out_dir else []:
            if d.exists():
                tmp = [p.name for p in d.rglob("*") if ".tmp-" in p.name]
                if tmp:
                    problems.append(f"temporary files left: {tmp[:3]}")
        if r.returncode != 0:
            for p, b in seeded.items():
                if not p.exists() or (p.is_file() and p.read_bytes() != b):
                    problems.append(f"{p.name} changed by a failed run")
        elif out_dir and out_dir.exists():
            for p in out_dir.rglob("*.png"):
                if p.is_symlink() or not p.is_file():
                    continue
                data = p.read_bytes()
                if not (data.startswith(b"\x89PNG") and b"IEND" in data[-12:]):
                    problems.append(f"{p.name} is not a whole PNG")
        if check:
            problems += check(r, err)
        self.record(cls, name, problems)
        return r

    # The classes.

    def scene_sets(self):
        keys = SET_KEYS if not self.quick else SET_KEYS[::3]
        for key, value in itertools.product(keys, HOSTILE_VALUES):
            d = self.folder()
            scene = d / "scene.toml"
            scene.write_text(BASE_SCENE)
            out = d / "out"
            seeded = {out / "left.png": b"old"}
            self.run("scene --set", f"{key}={value[:20]!r}",
                     ["render", str(scene), "--set", f"{key}={value}", "--out", str(out)],
                     out_dir=out, seeded=seeded)

    def scene_files(self):
        mutations = []
        for line in BASE_SCENE.splitlines():
            if "=" in line:
                k = line.split("=")[0].strip()
                for v in HOSTILE_VALUES[:: (2 if self.quick else 1)]:
                    mutations.append((k, line, f"{k} = {v}"))
        extra = ["\ufeff" + BASE_SCENE, BASE_SCENE.encode("utf-16-le").decode("latin-1"),
                 BASE_SCENE + "[camra]\nx = 1\n", BASE_SCENE.replace("[camera]", "[camera"),
                 BASE_SCENE + "\x1b]0;title\x07 = 1\n", BASE_SCENE * 2, ""]
        for k, old, new in mutations:
            d = self.folder()
            scene = d / "scene.toml"
            scene.write_text(BASE_SCENE.replace(old, new, 1))
            self.run("scene file", f"{new[:30]!r}", ["info", str(scene)])
        for i, text in enumerate(extra):
            d = self.folder()
            scene = d / "scene.toml"
            scene.write_bytes(text.encode("utf-8", "surrogatepass"))
            self.run("scene file", f"whole file {i}", ["info", str(scene)])

    def obj_files(self):
        good = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\n"
        for line in OBJ_LINES:
            d = self.folder()
            (d / "m.obj").write_bytes((good + line + "\n").encode("utf-8"))
            scene = d / "scene.toml"
            scene.write_text(BASE_SCENE.replace('kind = "cube"', 'kind = "obj"\npath = "m.obj"'))
            self.run("OBJ", repr(line[:30]), ["info", str(scene)],
                     check=lambda r, e: [] if r.returncode == 0 or "m.obj:" in e
                     else ["the error does not name the file and line"])

    def output_names(self):
        depth = self.work / "ramp.pgm"
        depth.write_bytes(b"P5\n64 32\n255\n" + bytes((i % 64) * 4 for i in range(64 * 32)))
        exts = ["png", "PNG", "jpg", "jpeg", "gif", "ppm", "pnm", "pgm", "pam", "bmp", "tiff",
                "webp", "txt", "", "png.tmp"]
        for ext in exts:
            for mode in ["scene", "depth"]:
                d = self.folder()
                out = d / (f"x.{ext}" if ext else "x")
                args = (["sirds", str(SCENES / "sirds_sphere.toml")] if mode == "scene"
                        else ["sirds", "--depth", str(depth)])
                self.run("container follows the name", f"{mode} -o x.{ext}",
                         args + ["-o", str(out)], out_dir=d,
                         check=lambda r, e, out=out: self.container_check(r, e, out))
        for flag, cmd, ext in [("--csv", ["bench", "--only", "nothing"], "txt"),
                               ("--json", ["grade", "ex9"], "txt"),
                               ("--out", ["grade", "bundle"], "tar")]:
            d = self.folder()
            self.run("container follows the name", f"{cmd[0]} {flag} x.{ext}",
                     cmd + [flag, str(d / f"x.{ext}")],
                     check=lambda r, e, flag=flag: [] if r.returncode != 0 and flag in e
                     else ["not refused naming the flag"])

    @staticmethod
    def container_check(r, err, out):
        if r.returncode != 0:
            return [] if not out.exists() else ["a refused name was written"]
        data = out.read_bytes()
        ext = out.suffix.lower()
        magic = {".png": b"\x89PNG", ".jpg": b"\xff\xd8", ".jpeg": b"\xff\xd8", ".gif": b"GIF8",
                 ".ppm": b"P6", ".pnm": b"P6", ".pgm": b"P5", ".pam": b"P7"}
        want = magic.get(ext)
        if want is None:
            return [f"wrote {out.name} in no format its name says"]
        return [] if data.startswith(want) else [f"{out.name} does not hold {ext} bytes"]

    def links_and_special_files(self):
        for name, make in [("a link", lambda p, v: p.symlink_to(v)),
                           ("a folder", lambda p, v: p.mkdir()),
                           ("a FIFO", lambda p, v: os.mkfifo(p))]:
            for output in ["parallax.png", "anaglyph_dubois.png"]:
                d = self.folder()
                victim = d / "victim.txt"
                victim.write_text("keep me")
                out = d / "out"
                out.mkdir()
                make(out / output, victim)
                self.run("links and special files", f"{output} is {name}",
                         ["render", str(SCENES / "anaglyph.toml"), "--size", "32x24",
                          "--out", str(out)], out_dir=out,
                         check=lambda r, e, victim=victim: ([] if r.returncode == 1 else
                                                           ["not refused"]) +
                         ([] if victim.read_text() == "keep me" else ["wrote through"]))
        for special in ["/dev/zero", "/dev/null", "/proc/self/mem"]:
            self.run("links and special files", f"scene {special}", ["info", special])
            self.run("links and special files", f"depth {special}",
                     ["sirds", "--depth", special, "-o", str(self.folder() / "x.png")])

    def signals(self):
        sigs = [(signal.SIGINT, 130), (signal.SIGTERM, 143), (signal.SIGHUP, 129)]
        delays = [0.05, 0.3, 1.0] if not self.quick else [0.3]
        for (sig, code), delay in itertools.product(sigs, delays):
            d = self.folder()
            gif = d / "turn.gif"
            seeded = {gif: b"old"}
            gif.write_bytes(b"old")
            p = subprocess.Popen([self.bin, "sirds", str(SCENES / "sirds_sphere.toml"),
                                  "--frames", "60", "-o", str(gif)],
                                 stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
            time.sleep(delay)
            p.send_signal(sig)
            try:
                _, err = p.communicate(timeout=60)
            except subprocess.TimeoutExpired:
                p.kill()
                self.record("signals", f"{sig.name} at {delay} s", ["did not end"])
                continue
            problems = []
            tmp = [x.name for x in d.iterdir() if ".tmp-" in x.name]
            if tmp:
                problems.append(f"left {tmp}")
            if p.returncode == 0:
                whole = gif.read_bytes()
                if not whole.startswith(b"GIF8"):
                    problems.append("finished but the GIF is not whole")
            elif p.returncode != code:
                problems.append(f"exit code {p.returncode}, not {code}")
            elif gif.read_bytes() != seeded[gif]:
                problems.append("the old file changed")
            self.record("signals", f"{sig.name} at {delay} s", problems)

    def file_size_limits(self):
        import resource
        for limit in [1, 100, 2000, 8000, 30000]:
            d = self.folder()
            out = d / "out"
            seeded = {out / n: b"old" for n in ["left.png", "right.png", "side_by_side.png"]}

            def lim(limit=limit):
                resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
            self.run("file-size limit", f"{limit} bytes",
                     ["render", str(SCENES / "wuson.toml"), "--size", "64x48", "--out", str(out)],
                     out_dir=out, seeded=seeded, preexec=lim,
                     check=lambda r, e: [] if r.returncode == 0 or "File too large" in e
                     else ["no 'File too large'"])

    def stale_temporaries(self):
        dead = subprocess.Popen(["true"])
        dead.wait()
        for age, pid, stays in [(3600, dead.pid, False), (0, dead.pid, True),
                                (3600, os.getpid(), True), (3600, 1, True)]:
            d = self.folder()
            out = d / "out"
            out.mkdir()
            t = out / f".left.png.tmp-{pid}-1a2b-0"
            t.write_bytes(b"half")
            os.utime(t, (time.time() - age, time.time() - age))
            r = subprocess.run([self.bin, "render", str(SCENES / "wuson.toml"), "--size",
                                "32x24", "--out", str(out)], capture_output=True)
            problems = [] if r.returncode == 0 else ["render failed"]
            if t.exists() != stays:
                problems.append("kept a stale file" if t.exists() else "removed a live one")
            self.record("stale temporaries", f"age {age} s, pid {pid}", problems)

    def resources(self):
        cases = [
            ("RAYON_NUM_THREADS=5000", ["render", str(SCENES / "wuson.toml"), "--size", "64x48"],
             {"RAYON_NUM_THREADS": "5000"}),
            ("RAYON_NUM_THREADS=abc", ["render", str(SCENES / "wuson.toml"), "--size", "64x48"],
             {"RAYON_NUM_THREADS": "abc"}),
            ("8192² under a 64 MiB budget", ["render", str(SCENES / "wuson.toml"), "--size",
                                             "8192x8192", "--max-memory", "64M"], {}),
            ("--max-memory nonsense", ["render", str(SCENES / "wuson.toml"),
                                       "--max-memory", "lots"], {}),
            ("16385 wide", ["render", str(SCENES / "wuson.toml"), "--size", "16385x2"], {}),
            ("frames 100000", ["sirds", str(SCENES / "sirds_sphere.toml"), "--frames",
                               "100000"], {}),
            ("max triangles", ["render", str(SCENES / "wuson.toml"), "--set",
                               "mesh.0.kind=\"sphere\"", "--set", "mesh.0.detail=4096"], {}),
        ]
        for name, args, env in cases:
            d = self.folder()
            out_flag = ["-o", str(d / "x.gif")] if args[0] == "sirds" else ["--out", str(d)]
            self.run("resources", name, args + out_flag, out_dir=d, env=env, timeout=90)

    def paths(self):
        d = self.folder()
        inside = d / "scene"
        inside.mkdir()
        (inside / "link.csv").symlink_to("/etc/passwd")
        (inside / "dangling.csv").symlink_to("/etc/nosuch-file")
        for path in ["/etc/passwd", "/etc/nosuch-file", "../../../etc/passwd",
                     "../../../etc/nosuch-file", "link.csv", "dangling.csv"]:
            scene = inside / "scene.toml"
            scene.write_text(BASE_SCENE.replace('kind = "cube"',
                                                f'kind = "terrain"\npath = "{path}"'))
            self.run("outside paths", path, ["info", str(scene)],
                     check=lambda r, e: [] if "names no file inside" in e
                     else ["not the one refusal"])

    def controls(self):
        """The unchanged inputs work: a case that fails for another reason proves nothing."""
        d = self.folder()
        scene = d / "scene.toml"
        scene.write_text(BASE_SCENE)
        self.run("controls", "the base scene renders",
                 ["render", str(scene), "--out", str(d / "out")], out_dir=d / "out",
                 expect_codes=(0,))
        (d / "m.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\n")
        scene.write_text(BASE_SCENE.replace('kind = "cube"', 'kind = "obj"\npath = "m.obj"'))
        self.run("controls", "the base OBJ loads", ["info", str(scene)], expect_codes=(0,))

    def all(self):
        for cls in [self.controls, self.scene_sets, self.scene_files, self.obj_files, self.output_names,
                    self.links_and_special_files, self.signals, self.file_size_limits,
                    self.stale_temporaries, self.resources, self.paths]:
            t = time.time()
            cls()
            print(f"{cls.__name__}: {time.time() - t:.0f} s", file=sys.stderr)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=str(ROOT / "target" / "debug" / "stereolab"))
    ap.add_argument("--quick", action="store_true", help="a third of the value products")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="stereolab-catalogue-") as work:
        c = Catalogue(a.bin, work, a.quick)
        c.all()
    total = sum(ok + bad for ok, bad in c.counts.values())
    for cls, (ok, bad) in c.counts.items():
        print(f"{cls:30} {ok + bad:5} cases, {bad} failing")
    for f in c.failures:
        print("FAIL", f)
    print(f"{total} cases, {len(c.failures)} failing")
    sys.exit(1 if c.failures else 0)


if __name__ == "__main__":
    main()
