#!/usr/bin/env python3
"""Bad-input sweep: every app on missing, empty, truncated,
bit-flipped and malformed inputs. Python standard library only.

  sweep.py list                      the case names, one per line (for CMake)
  sweep.py setup BIN_DIR DIR         writes every bad input into DIR (needs the
                                     apps and make_rawlogs in BIN_DIR)
  sweep.py run BIN_DIR DIR CASE      runs one case and checks it

A case passes when the app
  - exits with a non-zero status below 128 (no signal, no abort; 'clean'
    cases may also exit 0),
  - finishes within the time limit (no hang),
  - writes exactly one non-empty line to stderr, and that line names the bad
    input (its file name, and 'line N' / ':N' where a line is at fault).
"""
import os
import re
import shutil
import struct
import subprocess
import sys
import zlib

TIMEOUT_S = 120
SHARE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "share", "codemark")


# ---------------------------------------------------------------- inputs
def png(path, width, height, depth=8, colour=0, value=128, raw_ihdr=False):
    """A PNG written by hand (zlib + struct): any size, grey or RGB, 8 or 16 bit."""
    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)
    channels = 3 if colour == 2 else 1
    bpp = channels * depth // 8
    comp = zlib.compressobj(9)
    body = b""
    row = b"\x00" + bytes([value % 256]) * (width * bpp)
    for _ in range(height):
        body += comp.compress(row)
    body += comp.flush()
    ihdr = struct.pack(">IIBBBBB", width, height, depth, colour, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", body) + chunk(b"IEND", b""))


def write(path, text):
    with open(path, "w") as f:
        f.write(text)


def flipped(src, dst, every=97, seed=12345):
    """A copy of src with one bit flipped in every `every` bytes after the first 64."""
    data = bytearray(open(src, "rb").read())
    x = seed
    for i in range(64, len(data), every):
        x = (1103515245 * x + 12345) & 0x7FFFFFFF
        data[i] ^= 1 << (x % 8)
    open(dst, "wb").write(bytes(data))


def truncated(src, dst, fraction=0.6):
    data = open(src, "rb").read()
    open(dst, "wb").write(data[: int(len(data) * fraction)])


def run(cmd):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=600)
    if r.returncode != 0:
        sys.exit("setup failed: %s\n%s%s" % (" ".join(cmd), r.stdout, r.stderr))


def setup(bin_dir, d):
    if os.path.isdir(d):
        shutil.rmtree(d)
    os.makedirs(d)
    exe = lambda n: os.path.join(bin_dir, n)
    # A small valid dataset of each rawlog format, annotated.
    run([exe("codemark-simul"), "-q", "-o", os.path.join(d, "ds"), "--max-frames", "6"])
    run([exe("codemark-simul"), "-q", "--obs-only", "-o", os.path.join(d, "dso"), "--max-frames", "6"])
    run([exe("codemark-annotate"), "-q", "--threads", "1", "-i", os.path.join(d, "ds", "dataset.rawlog"),
         "-o", os.path.join(d, "good.rawlog"), "--drop-images"])
    run([exe("codemark-annotate"), "-q", "--threads", "1", "-i", os.path.join(d, "dso", "dataset.rawlog"),
         "-o", os.path.join(d, "good_obs.rawlog"), "--drop-images"])
    shutil.copy(os.path.join(d, "ds", "map.txt"), os.path.join(d, "map.txt"))
    good = os.path.join(d, "good.rawlog")
    # Damaged rawlogs.
    truncated(good, os.path.join(d, "truncated.rawlog"))
    flipped(good, os.path.join(d, "bitflip.rawlog"))
    write(os.path.join(d, "empty.rawlog"), "")
    write(os.path.join(d, "text.rawlog"), "this is not a rawlog\n")
    mk = exe("make_rawlogs")
    run([mk, "nan-odometry", good, os.path.join(d, "nan_odo.rawlog")])
    run([mk, "inf-odometry", good, os.path.join(d, "inf_odo.rawlog")])
    run([mk, "nan-odometry", os.path.join(d, "good_obs.rawlog"), os.path.join(d, "nan_odo_obs.rawlog")])
    run([mk, "nan-observation", good, os.path.join(d, "nan_obs.rawlog")])
    run([mk, "scans", os.path.join(d, "scans.rawlog")])
    run([mk, "foreign", os.path.join(d, "foreign.rawlog")])
    # Images, standalone and inside one-image rawlogs (external storage).
    images = {
        "img_empty.png": None,
        "img_0x0.png": (0, 0, 8, 0),
        "img_1x1.png": (1, 1, 8, 2),
        "img_grey.png": (640, 480, 8, 0),
        "img_16bit.png": (640, 480, 16, 2),
        "img_huge.png": (8000, 8000, 8, 0),
    }
    for name, spec in images.items():
        p = os.path.join(d, name)
        if spec is None:
            write(p, "")
        else:
            png(p, *spec)
        stem = "rl_" + name[4:-4]
        os.makedirs(os.path.join(d, stem + "_Images"))
        shutil.copy(p, os.path.join(d, stem + "_Images", name))
        run([mk, "image", os.path.join(d, stem + ".rawlog"), name])
    run([mk, "image", os.path.join(d, "rl_noimage.rawlog"), "not_there.png"])
    # Map files.
    write(os.path.join(d, "map_badnum.txt"), "# id x y z yaw\n17 6.0 1.5 0.6 180\n18 6.0 abc 0.6 180\n")
    write(os.path.join(d, "map_missing.txt"), "17 6.0 1.5 0.6 180\n18 6.0 3.0\n")
    write(os.path.join(d, "map_nan.txt"), "17 6.0 1.5 0.6 180\n18 nan 3.0 0.6 180\n")
    write(os.path.join(d, "map_inf.txt"), "17 6.0 1.5 0.6 inf\n")
    write(os.path.join(d, "map_nolm.txt"), "# a map without landmarks\n\n")
    write(os.path.join(d, "empty.txt"), "")
    # Camera files.
    cam = open(os.path.join(SHARE, "camera-paper.ini")).read()
    write(os.path.join(d, "cam_badnum.ini"), cam.replace("fx               = 800", "fx = 8o0"))
    write(os.path.join(d, "cam_nan.ini"), cam.replace("fx               = 800", "fx = nan"))
    write(os.path.join(d, "cam_missing.ini"), re.sub(r"\nfx .*\n", "\n", cam))
    write(os.path.join(d, "cam_nosection.ini"), cam.replace("[CAMERA_PARAMS]", "[SOMETHING]"))
    write(os.path.join(d, "cam_badres.ini"), cam.replace("[640 480]", "[640 x]"))
    write(os.path.join(d, "empty.ini"), "")
    ros = ("image_width: 640\nimage_height: 480\ncamera_name: c\ncamera_matrix:\n  rows: 3\n  cols: 3\n"
           "  data: [800, 0, 319.5, 0, 800, 239.5, 0, 0, 1]\ndistortion_model: plumb_bob\n"
           "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [0, 0, 0, 0, 0]\n")
    write(os.path.join(d, "cam_badnum.yaml"), ros.replace("800, 0, 319.5", "8x0, 0, 319.5"))
    write(os.path.join(d, "cam_missing.yaml"), ros.replace("image_height: 480\n", ""))
    write(os.path.join(d, "cam_short.yaml"), ros.replace("0, 0, 1]", "0]"))
    write(os.path.join(d, "cam_garbage.yaml"), "image_width: [640\n: : :\n")
    write(os.path.join(d, "empty.yaml"), "")
    # Landmark geometry and other inis.
    lm = open(os.path.join(SHARE, "landmark.ini")).read()
    write(os.path.join(d, "lm_badnum.ini"), lm.replace("outer_size_m = 0.200", "outer_size_m = 0.2x"))
    write(os.path.join(d, "lm_neg.ini"), lm.replace("outer_size_m = 0.200", "outer_size_m = -0.2"))
    write(os.path.join(d, "simul_badnum.ini"), "[map]\nroom_width_m = six\n")
    write(os.path.join(d, "simul_nomap.ini"), "[map]\nmap_file = %s\n" % os.path.join(d, "does_not_exist.txt"))
    write(os.path.join(d, "simul_badmap.ini"), "[map]\nmap_file = %s\n" % os.path.join(d, "map_badnum.txt"))
    write(os.path.join(d, "simul_nolm.ini"), "[map]\nmap_file = %s\n" % os.path.join(d, "map_nolm.txt"))
    write(os.path.join(d, "poses_nan.txt"), "1 0 0.6 0 0 0\n2 0 nan 0 0 0\n")
    write(os.path.join(d, "gt_badnum.txt"), "1700000000.0 1.0 1.0 zero\n")
    # Calibration files (docs/calibration.md).
    cal = open(os.path.join(SHARE, "calibration", "realistic.ini")).read()
    write(os.path.join(d, "cal_badcorr.ini"), re.sub(r"\ncorr_y12 = .*\n", "\ncorr_y12 = 1.5\n", cal))
    write(os.path.join(d, "cal_missing.ini"), re.sub(r"\ncorr_y12 = .*\n", "\n", cal))
    write(os.path.join(d, "cal_unknown.ini"), cal + "sigma_pixels = 0.1\n")
    write(os.path.join(d, "cal_nan.ini"), re.sub(r"\nsigma_px = .*\n", "\nsigma_px = nan\n", cal))
    open(os.path.join(d, "setup.done"), "w").close()


# ----------------------------------------------------------------- cases
# name: (app, [args] with {d} = input dir and {o} = a fresh output dir,
#        expect = 'reject' | 'clean', regex the error line must match)
LOC = ["-c", "{share}/config/ekf.ini", "-q", "-o", "{o}"]


def loc(rawlog, mapf="{d}/map.txt", extra=()):
    return LOC + ["-r", rawlog, "-m", mapf] + list(extra)


CASES = {}


def case(app, name, args, where, expect="reject"):
    CASES["%s.%s" % (app.replace("codemark-", ""), name)] = (app, args, expect, where)


for f, where in [("does_not_exist.ini", "does_not_exist.ini"), ("empty.ini", "empty.ini"),
                 ("lm_badnum.ini", "lm_badnum.ini.*outer_size_m"), ("lm_neg.ini", "lm_neg.ini.*outer_size_m")]:
    case("codemark-print", "landmark_" + f.split(".")[0], ["--id", "17", "--out", "{o}", "--landmark", "{d}/" + f], where)
case("codemark-print", "id_out_of_range", ["--id", "300", "--out", "{o}"], "300")
case("codemark-print", "id_not_a_number", ["--id", "x7", "--out", "{o}"], "x7")

for f, where in [("does_not_exist.txt", "does_not_exist.txt"), ("empty.txt", "empty.txt"),
                 ("map_nolm.txt", "map_nolm.txt"), ("map_badnum.txt", "map_badnum.txt:3"),
                 ("map_missing.txt", "map_missing.txt:2"), ("map_nan.txt", "map_nan.txt:2"),
                 ("map_inf.txt", "map_inf.txt:1")]:
    case("codemark-render", "map_" + f.split(".")[0].replace("map_", ""), ["-q", "-m", "{d}/" + f, "-o", "{o}"], where)
for f in ["does_not_exist.ini", "empty.ini", "cam_badnum.ini", "cam_nan.ini", "cam_missing.ini",
          "cam_nosection.ini", "cam_badres.ini", "cam_badnum.yaml", "cam_missing.yaml", "cam_short.yaml",
          "cam_garbage.yaml", "empty.yaml"]:
    case("codemark-render", "camera_" + f.replace(".", "_"), ["-q", "-m", "{d}/map.txt", "-o", "{o}", "-c", "{d}/" + f],
         re.escape(f))
case("codemark-render", "poses_nan", ["-q", "-m", "{d}/map.txt", "-o", "{o}", "-p", "{d}/poses_nan.txt"],
     "poses_nan.txt:2")

for f in ["does_not_exist.png", "img_empty.png", "img_0x0.png", "img_1x1.png", "img_16bit.png", "img_huge.png"]:
    case("codemark-detect", "image_" + f.split(".")[0].replace("img_", ""), ["{d}/" + f], re.escape(f))
case("codemark-detect", "image_grey", ["{d}/img_grey.png"], "img_grey.png", expect="clean")
for f in ["does_not_exist.ini", "cam_badnum.ini", "cam_missing.yaml"]:
    case("codemark-detect", "camera_" + f.replace(".", "_"), ["--camera", "{d}/" + f, "{d}/img_grey.png"], re.escape(f))

for f in ["does_not_exist.ini", "cam_badnum.ini", "cam_missing.ini", "cam_badnum.yaml"]:
    case("codemark-uncertainty", "camera_" + f.replace(".", "_"), ["--camera", "{d}/" + f, "--table"], re.escape(f))
CAL = [("does_not_exist.ini", "does_not_exist.ini"), ("cal_badcorr.ini", r"cal_badcorr.ini:\d+: corr_y12"),
       ("cal_missing.ini", "cal_missing.ini.*corr_y12"), ("cal_unknown.ini", r"cal_unknown.ini:\d+: .*sigma_pixels"),
       ("cal_nan.ini", r"cal_nan.ini:\d+: sigma_px"), ("no-such-name", "no-such-name")]
for f, where in CAL:
    n = "calibration_" + f.split(".")[0].replace("cal_", "").replace("-", "_")
    case("codemark-uncertainty", n, ["--calibration", "{d}/" + f if "." in f else f, "--table"], where)
    case("codemark-detect", n, ["--calibration", "{d}/" + f if "." in f else f, "{d}/img_grey.png"], where)
case("codemark-uncertainty", "sigma_nan", ["--sigma-px", "nan", "--table"], "sigma")
case("codemark-uncertainty", "size_for_bad", ["--size-for", "0.1,abc"], "size-for")

for f in ["does_not_exist.ini", "cam_badnum.ini", "cam_missing.yaml"]:
    case("codemark-accuracy-map", "camera_" + f.replace(".", "_"), ["--out", "{o}", "--no-apriltag", "--camera", "{d}/" + f],
         re.escape(f))
case("codemark-accuracy-map", "cell_zero", ["--out", "{o}", "--no-apriltag", "--cell", "0"], "cell")
case("codemark-accuracy-map", "cell_nan", ["--out", "{o}", "--no-apriltag", "--cell", "nan"], "cell")

for f, where in [("does_not_exist.ini", "does_not_exist.ini"), ("simul_badnum.ini", "simul_badnum.ini.*room_width_m"),
                 ("simul_nomap.ini", "does_not_exist.txt"), ("simul_badmap.ini", "map_badnum.txt:3"),
                 ("simul_nolm.ini", "map_nolm.txt")]:
    case("codemark-simul", "config_" + f.split(".")[0].replace("simul_", ""), ["-q", "-c", "{d}/" + f, "-o", "{o}"], where)

ANN = ["-q", "--threads", "1", "-o", "{o}/out.rawlog"]
for f in ["does_not_exist.rawlog", "empty.rawlog", "text.rawlog", "truncated.rawlog", "bitflip.rawlog",
          "scans.rawlog", "foreign.rawlog", "rl_empty.rawlog", "rl_0x0.rawlog", "rl_1x1.rawlog", "rl_16bit.rawlog",
          "rl_huge.rawlog", "rl_noimage.rawlog"]:
    case("codemark-annotate", "rawlog_" + f.split(".")[0], ANN + ["-i", "{d}/" + f], re.escape(f))
case("codemark-annotate", "camera_badnum", ANN + ["-i", "{d}/ds/dataset.rawlog", "--camera", "{d}/cam_badnum.ini"],
     "cam_badnum.ini")
case("codemark-annotate", "map_badnum", ANN + ["-i", "{d}/ds/dataset.rawlog", "--map", "{d}/map_badnum.txt"],
     "map_badnum.txt:3")
case("codemark-annotate", "calibration_badcorr",
     ANN + ["-i", "{d}/ds/dataset.rawlog", "--calibration", "{d}/cal_badcorr.ini"], r"cal_badcorr.ini:\d+: corr_y12")
case("codemark-annotate", "landmark_badnum", ANN + ["-i", "{d}/ds/dataset.rawlog", "--landmark", "{d}/lm_badnum.ini"],
     "lm_badnum.ini")

for f in ["does_not_exist.rawlog", "empty.rawlog", "text.rawlog", "truncated.rawlog", "bitflip.rawlog",
          "scans.rawlog", "foreign.rawlog", "nan_odo.rawlog", "inf_odo.rawlog", "nan_odo_obs.rawlog",
          "nan_obs.rawlog", "rl_1x1.rawlog", "rl_16bit.rawlog"]:
    case("codemark-localize", "rawlog_" + f.split(".")[0], loc("{d}/" + f), re.escape(f))
for f, where in [("does_not_exist.txt", "does_not_exist.txt"), ("empty.txt", "empty.txt"),
                 ("map_nolm.txt", "map_nolm.txt"), ("map_badnum.txt", "map_badnum.txt:3")]:
    case("codemark-localize", "map_" + f.split(".")[0].replace("map_", ""), loc("{d}/good.rawlog", "{d}/" + f), where)
case("codemark-localize", "config_missing",
     ["-c", "{d}/does_not_exist.ini", "-q", "-o", "{o}", "-r", "{d}/good.rawlog", "-m", "{d}/map.txt"],
     "does_not_exist.ini")
case("codemark-localize", "calibration_badcorr",
     loc("{d}/good.rawlog", extra=["--calibration", "{d}/cal_badcorr.ini"]), r"cal_badcorr.ini:\d+: corr_y12")
case("codemark-localize", "calibration_missing", loc("{d}/good.rawlog", extra=["--calibration", "{d}/cal_missing.ini"]),
     "cal_missing.ini.*corr_y12")
# An annotated rawlog measured again with another shipped calibration.
case("codemark-localize", "calibration_plain", loc("{d}/good.rawlog", extra=["--calibration", "plain"]), "",
     expect="clean")
case("codemark-accuracy-map", "calibration_badcorr",
     ["--out", "{o}", "--no-apriltag", "--calibration", "{d}/cal_badcorr.ini"], r"cal_badcorr.ini:\d+: corr_y12")
case("codemark-localize", "gt_badnum", loc("{d}/good.rawlog", extra=["-g", "{d}/gt_badnum.txt"]), "gt_badnum.txt:1")

# codemark-calibrate-noise: the run, the map, the starting calibration and
# the config; --scale without a run.
CAL_NOISE = ["-q", "-o", "{o}/fit.ini"]
for f in ["does_not_exist.rawlog", "empty.rawlog", "text.rawlog", "truncated.rawlog", "bitflip.rawlog",
          "scans.rawlog", "foreign.rawlog", "nan_odo.rawlog"]:
    case("codemark-calibrate-noise", "rawlog_" + f.split(".")[0], CAL_NOISE + ["-r", "{d}/" + f, "-m", "{d}/map.txt"],
         re.escape(f))
for f, where in [("does_not_exist.txt", "does_not_exist.txt"), ("map_nolm.txt", "map_nolm.txt"),
                 ("map_badnum.txt", "map_badnum.txt:3")]:
    case("codemark-calibrate-noise", "map_" + f.split(".")[0].replace("map_", ""),
         CAL_NOISE + ["-r", "{d}/good.rawlog", "-m", "{d}/" + f], where)
case("codemark-calibrate-noise", "calibration_badcorr",
     CAL_NOISE + ["-r", "{d}/good.rawlog", "-m", "{d}/map.txt", "--calibration", "{d}/cal_badcorr.ini"],
     r"cal_badcorr.ini:\d+: corr_y12")
case("codemark-calibrate-noise", "config_missing",
     CAL_NOISE + ["-r", "{d}/good.rawlog", "-m", "{d}/map.txt", "-c", "{d}/does_not_exist.ini"], "does_not_exist.ini")
case("codemark-calibrate-noise", "no_rawlog", CAL_NOISE + ["-m", "{d}/map.txt"], "rawlog")
case("codemark-calibrate-noise", "scale_zero", CAL_NOISE + ["--scale", "0"], "scale")
case("codemark-calibrate-noise", "scale_nan", CAL_NOISE + ["--scale", "nan"], "scale")
case("codemark-calibrate-noise", "scale_with_run", CAL_NOISE + ["--scale", "2", "-r", "{d}/good.rawlog"], "scale")
case("codemark-calibrate-noise", "scale_badcorr", CAL_NOISE + ["--scale", "2", "--calibration", "{d}/cal_badcorr.ini"],
     r"cal_badcorr.ini:\d+: corr_y12")
case("codemark-calibrate-noise", "scale_family", CAL_NOISE + ["--scale", "2", "--calibration", "family"], "",
     expect="clean")

# codemark-bench (if built): a missing and an empty datasets ini.
case("codemark-bench", "config_missing", ["{d}/does_not_exist.ini"], "does_not_exist.ini")
case("codemark-bench", "config_empty", ["{d}/empty.ini"], "empty.ini")


# Every app: a mistyped option, named on one line in the tools' common form,
# and (where arguments are required) none at all.
for app in ["codemark-print", "codemark-render", "codemark-detect", "codemark-annotate", "codemark-localize",
            "codemark-simul", "codemark-uncertainty", "codemark-calibrate-noise", "codemark-bench"]:
    case(app, "unknown_option", ["--no-such-option"],
         "^%s: error: --no-such-option: .*\\(see --help\\)$" % app)
    if app != "codemark-uncertainty":
        case(app, "no_arguments", [], "^%s: error: Required argument.*\\(see --help\\)$" % app)


# ------------------------------------------------------------------ check
def check(bin_dir, d, name):
    app, args, expect, where = CASES[name]
    out = os.path.join(d, "out", name + "." + str(os.getpid()))
    os.makedirs(out, exist_ok=True)
    argv = [os.path.join(bin_dir, app)] + [a.format(d=d, o=out, share=SHARE) for a in args]
    print("$ " + " ".join(argv))
    try:
        r = subprocess.run(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=TIMEOUT_S)
    except subprocess.TimeoutExpired:
        print("FAIL: no exit within %d s (hang)" % TIMEOUT_S)
        return 1
    finally:
        pass
    err = r.stderr.decode("utf-8", "replace")
    print("exit status: %d\nstderr:\n%s" % (r.returncode, err))
    shutil.rmtree(out, ignore_errors=True)
    problems = []
    if r.returncode < 0:
        problems.append("killed by signal %d" % -r.returncode)
    elif r.returncode >= 128:
        problems.append("exit status %d >= 128 (abort or signal)" % r.returncode)
    elif r.returncode == 0 and expect == "reject":
        problems.append("exit status 0: the bad input was accepted")
    # libpng prints its own warnings from inside OpenCV's decoder, which no
    # caller can silence; they do not count as the app's error lines.
    lines = [l for l in err.splitlines() if l.strip() and not l.startswith("libpng ")]
    if r.returncode != 0 and r.returncode < 128:
        if len(lines) != 1:
            problems.append("stderr has %d non-empty lines, expected exactly one" % len(lines))
        if not re.search(where, err):
            problems.append("stderr does not name the bad input (expected /%s/)" % where)
    for p in problems:
        print("FAIL: " + p)
    if not problems:
        print("PASS")
    return 1 if problems else 0


def main():
    if len(sys.argv) == 2 and sys.argv[1] == "list":
        for n, (app, *_rest) in CASES.items():
            print("%s %s" % (n, app))
        return 0
    if len(sys.argv) == 4 and sys.argv[1] == "setup":
        setup(sys.argv[2], sys.argv[3])
        return 0
    if len(sys.argv) == 5 and sys.argv[1] == "run":
        return check(sys.argv[2], sys.argv[3], sys.argv[4])
    sys.exit(__doc__)


if __name__ == "__main__":
    sys.exit(main())
