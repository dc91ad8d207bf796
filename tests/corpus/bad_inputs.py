#!/usr/bin/env python3
"""Bad-input corpus for geardiag's readers and output paths (docs/limits.md).

Generates damaged inputs (CSV, CSV.gz, WAV, MAT, HDF5, channel maps, face-gear tables, special
files, bad output paths, full disks) into DIR, runs the geardiag binary on each, and checks that
every case
  - exits with code 2 (bad input; never 0, 1, 3, a signal or a hang),
  - prints a message naming the file (or option) and the expected reason,
  - leaves no output and no temporary file (and a previous output, where there is one, unchanged),
  - finishes within TIME_LIMIT_S seconds.
A full disk is a file size limit on the run (RLIMIT_FSIZE with SIGXFSZ ignored: writes past it fail
as on a full disk), so those cases run wherever the test runs, without a mount or privileges.

usage: bad_inputs.py --geardiag BIN --dir DIR [--generate-only] [--filter SUBSTRING]
exit 0 when every case passes. --generate-only writes the files (fuzzing seeds) and exits.

Needs numpy, scipy and h5py (scripts/install-deps installs them).
"""
import argparse
import gzip
import resource
import signal
import json
import os
import shutil
import struct
import subprocess
import sys
import time
import zlib

import h5py
import numpy as np
import scipy.io

# A case may take this long [s]. Legitimate refusals take milliseconds; the HDF5 reader's
# survey child (hdf5.cpp) gives up after 30 s, so a hang is reported within this limit.
TIME_LIMIT_S = 40


def csv_text(rows=50, fs=1000.0):
    lines = ["time,a,b"]
    for i in range(rows):
        lines.append(f"{i / fs:.6f},{np.sin(0.1 * i):.17g},{i}")
    return "\n".join(lines) + "\n"


def write(path, data):
    with open(path, "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def wav_bytes(samples, fs=8000, channels=1):
    data = (np.asarray(samples) * 32767).astype("<i2").tobytes()
    fmt = struct.pack("<HHIIHH", 1, channels, fs, fs * 2 * channels, 2 * channels, 16)
    body = b"WAVE" + b"fmt " + struct.pack("<I", len(fmt)) + fmt
    body += b"data" + struct.pack("<I", len(data)) + data
    return b"RIFF" + struct.pack("<I", len(body)) + body


def float_wav_bytes(samples, fs=8000):
    data = np.asarray(samples, dtype="<f4").tobytes()
    fmt = struct.pack("<HHIIHH", 3, 1, fs, fs * 4, 4, 32)
    body = b"WAVE" + b"fmt " + struct.pack("<I", len(fmt)) + fmt
    body += b"data" + struct.pack("<I", len(data)) + data
    return b"RIFF" + struct.pack("<I", len(body)) + body


def mat4_bytes(name, values):
    values = np.asarray(values, dtype="<f8")
    head = struct.pack("<5i", 0, len(values), 1, 0, len(name) + 1)
    return head + name.encode() + b"\0" + values.tobytes()


class Corpus:
    def __init__(self, binary, root):
        self.binary = binary
        self.root = root
        self.cases = []  # (name, argv, expected substrings, output paths, options)

    def path(self, name):
        return os.path.join(self.root, "inputs", name)

    def out(self, case):
        d = os.path.join(self.root, "out", case)
        os.makedirs(d, exist_ok=True)
        return d

    def add(self, name, argv, expect, outputs=(), fsize=None, keep=None, env=None):
        """fsize: the run's file size limit [bytes] (a full disk); keep: a previous output that
        must come out unchanged; env: variables set for the run."""
        self.cases.append((name, argv, expect, list(outputs),
                           {"fsize": fsize, "keep": keep, "env": env}))

    def import_case(self, name, file, expect, extra=()):
        out = os.path.join(self.out(name), "out.h5")
        self.add(name, ["import", file, "-o", out, *extra], expect, [out])

    def all_readers(self, name, file, expect, extra=(), info=True):
        """import, info and analyze each read the file (info only its metadata)."""
        self.import_case(name + "/import", file, expect, extra)
        if info:
            self.add(name + "/info", ["info", file, *extra], expect)
        js = os.path.join(self.out(name + "/analyze"), "a.json")
        self.add(name + "/analyze", ["analyze", file, "--json", js, *extra], expect, [js])


def generate(c):
    os.makedirs(os.path.join(c.root, "inputs"), exist_ok=True)
    p = c.path

    # ---- CSV ------------------------------------------------------------------------------
    good = csv_text()
    write(p("nul_byte.csv"), "a,b\n1,2\n3\0,4\n5,6\n")
    c.import_case("csv_nul_byte", p("nul_byte.csv"), ["nul_byte.csv", "line 3", "NUL byte"],
                  ["--fs", "100"])
    write(p("ragged.csv"), good.replace("\n0.000003,", "\n0.000003,1,", 1) + "1,2\n")
    c.all_readers("csv_ragged", p("ragged.csv"), ["ragged.csv", "ragged"])
    write(p("not_number.csv"), "time,a\n0,1\n0.001,x1\n")
    c.all_readers("csv_not_number", p("not_number.csv"), ["not_number.csv", "line 3", "not a number"])
    write(p("nan.csv"), "time,a\n0,1\n0.001,nan\n0.002,1\n")
    c.import_case("csv_nan", p("nan.csv"), ["nan.csv", "NaN"])
    write(p("inf.csv"), "time,a\n0,1\n0.001,inf\n0.002,1\n")
    c.import_case("csv_inf", p("inf.csv"), ["inf.csv", "infinite"])
    write(p("header_only.csv"), "time,a,b\n")
    c.import_case("csv_header_only", p("header_only.csv"), ["header_only.csv", "no data rows"])
    write(p("empty.csv"), b"")
    c.all_readers("csv_empty", p("empty.csv"), ["empty.csv", "empty file"])
    write(p("blank.csv"), "\n \n\t\n")
    c.import_case("csv_blank", p("blank.csv"), ["blank.csv", "no header row"])
    write(p("no_time.csv"), "a,b\n1,2\n3,4\n")
    c.import_case("csv_no_rate", p("no_time.csv"), ["no_time.csv", "fs_hz"])
    write(p("uneven.csv"), "time,a\n0,1\n0.001,2\n0.0025,3\n0.003,4\n")
    c.import_case("csv_uneven_time", p("uneven.csv"), ["uneven.csv", "not uniformly spaced"])
    write(p("decreasing.csv"), "time,a\n0.003,1\n0.002,2\n0.001,3\n")
    c.import_case("csv_decreasing_time", p("decreasing.csv"), ["decreasing.csv", "must increase"])
    write(p("dup.csv"), "time,a,a\n0,1,2\n")
    c.import_case("csv_duplicate_column", p("dup.csv"), ["dup.csv", "appears twice"])
    write(p("garbage.csv"), bytes(range(256)) * 4)
    c.import_case("csv_binary", p("garbage.csv"), ["garbage.csv", "NUL byte"], ["--fs", "100"])
    write(p("good.csv"), good)
    c.import_case("csv_fs_disagrees_with_time", p("good.csv"), ["good.csv", "fs_hz", "disagrees"],
                  ["--fs", "50"])
    write(p("time_only.csv"), "time\n0\n0.001\n")
    c.import_case("csv_time_only", p("time_only.csv"), ["time_only.csv", "no data columns"])
    write(p("one_row.csv"), "time,a\n0,1\n")
    c.import_case("csv_one_row", p("one_row.csv"), ["one_row.csv", "one time stamp"])
    c.import_case("csv_fs_negative", p("no_time.csv"), ["fs_hz"], ["--fs", "-5"])

    # ---- CSV.gz ---------------------------------------------------------------------------
    gz = gzip.compress(good.encode() * 20, mtime=0)
    write(p("truncated.csv.gz"), gz[: len(gz) // 2])
    c.all_readers("gz_truncated", p("truncated.csv.gz"), ["truncated.csv.gz", "truncated gzip"])
    write(p("trailer_cut.csv.gz"), gz[:-4])
    c.import_case("gz_trailer_cut", p("trailer_cut.csv.gz"), ["trailer_cut.csv.gz", "gzip"])
    write(p("plain.csv.gz"), good)
    c.import_case("gz_not_gzip", p("plain.csv.gz"), ["plain.csv.gz", "not gzip"])
    bad_crc = bytearray(gz)
    bad_crc[-6] ^= 0xFF
    write(p("bad_crc.csv.gz"), bytes(bad_crc))
    c.import_case("gz_bad_crc", p("bad_crc.csv.gz"), ["bad_crc.csv.gz", "gzip"])
    bad_deflate = bytearray(gz)
    for i in range(20, 40):
        bad_deflate[i] ^= 0x5A
    write(p("bad_deflate.csv.gz"), bytes(bad_deflate))
    c.import_case("gz_corrupt", p("bad_deflate.csv.gz"), ["bad_deflate.csv.gz"])
    write(p("nul.csv.gz"), gzip.compress(b"time,a\n0,1\n0.001,\0\n", mtime=0))
    c.import_case("gz_nul_byte", p("nul.csv.gz"), ["nul.csv.gz", "NUL byte"])

    # ---- WAV ------------------------------------------------------------------------------
    wav = wav_bytes(np.sin(np.arange(4000) * 0.05))
    write(p("truncated.wav"), wav[: len(wav) // 2])
    c.all_readers("wav_truncated", p("truncated.wav"), ["truncated.wav", "truncated"])
    write(p("header_only.wav"), wav_bytes([])[:44])
    c.import_case("wav_no_samples", p("header_only.wav"), ["header_only.wav", "no samples"])
    write(p("garbage.wav"), bytes((i * 37) % 251 + 1 for i in range(3000)))
    c.import_case("wav_garbage", p("garbage.wav"), ["garbage.wav", "unrecognised format"])
    write(p("nan.wav"), float_wav_bytes([0.0, 0.5, float("nan"), 0.1]))
    c.import_case("wav_nan", p("nan.wav"), ["nan.wav", "NaN"])

    # ---- MAT ------------------------------------------------------------------------------
    x = np.sin(np.arange(5000) * 0.01)
    scipy.io.savemat(p("good.mat"), {"DE_time": x.reshape(-1, 1), "RPM": np.array([[1797.0]])})
    scipy.io.savemat(p("good_z.mat"), {"DE_time": x.reshape(-1, 1)}, do_compression=True)
    mat = open(p("good.mat"), "rb").read()
    matz = open(p("good_z.mat"), "rb").read()
    write(p("truncated.mat"), mat[: len(mat) // 2])
    c.all_readers("mat_truncated", p("truncated.mat"), ["truncated.mat", "truncated"],
                  ["--fs", "12000"])
    write(p("truncated_z.mat"), matz[: len(matz) // 2])
    c.import_case("mat_compressed_truncated", p("truncated_z.mat"), ["truncated_z.mat", "variable 1"],
                  ["--fs", "12000"])
    corrupt_z = bytearray(matz)
    for i in range(200, 260):
        corrupt_z[i] ^= 0xA5
    write(p("corrupt_z.mat"), bytes(corrupt_z))
    c.import_case("mat_compressed_corrupt", p("corrupt_z.mat"), ["corrupt_z.mat", "compressed"],
                  ["--fs", "12000"])
    # The first variable's dimensions say 10^8 rows: the real part holds only 5000 values.
    lie = bytearray(mat)
    dims_at = 128 + 8 + 16 + 8  # file header, matrix tag, array flags, dims tag
    lie[dims_at: dims_at + 4] = struct.pack("<i", 100_000_000)
    write(p("dims_lie.mat"), bytes(lie))
    c.import_case("mat_dims_lie", p("dims_lie.mat"), ["dims_lie.mat", "DE_time"], ["--fs", "12000"])
    # The last variable cut: must not be dropped silently.
    write(p("last_cut.mat"), mat[:-8])
    c.import_case("mat_last_variable_cut", p("last_cut.mat"), ["last_cut.mat", "variable 2"],
                  ["--fs", "12000"])
    scipy.io.savemat(p("matrix_only.mat"), {"image": np.ones((3, 4))})
    c.import_case("mat_no_vectors", p("matrix_only.mat"), ["matrix_only.mat", "no numeric vector"],
                  ["--fs", "12000"])
    c.import_case("mat_without_fs", p("good.mat"), ["good.mat", "fs_hz"])
    write(p("garbage.mat"), bytes((i * 91) % 253 + 2 for i in range(4000)))
    c.import_case("mat_garbage", p("garbage.mat"), ["garbage.mat", "not a MATLAB"], ["--fs", "100"])
    scipy.io.savemat(p("nan.mat"), {"x": np.array([0.0, np.nan, 1.0])})
    c.import_case("mat_nan", p("nan.mat"), ["nan.mat", "NaN"], ["--fs", "100"])
    v4 = mat4_bytes("x", np.arange(100.0))
    write(p("v4_truncated.mat"), v4[:-16])
    c.import_case("mat_v4_truncated", p("v4_truncated.mat"), ["v4_truncated.mat", "truncated"],
                  ["--fs", "100"])
    bad_type = bytearray(mat)
    bad_type[128 + 8 + 16 + 8 + 8 + 8 + 8] = 99  # real part's data type
    write(p("bad_type.mat"), bytes(bad_type))
    c.import_case("mat_bad_data_type", p("bad_type.mat"), ["bad_type.mat", "DE_time"],
                  ["--fs", "12000"])

    # ---- HDF5 -----------------------------------------------------------------------------
    base = p("base.h5")
    r = subprocess.run([c.binary, "import", p("good.csv"), "-o", base], capture_output=True)
    if r.returncode != 0:
        sys.exit(f"bad_inputs.py: cannot make the base recording: {r.stderr.decode()}")
    raw = p("base_raw.h5")
    subprocess.run([c.binary, "import", p("good.csv"), "-o", raw, "--deflate", "0"], check=True,
                   capture_output=True)

    def variant(name, edit, source=base):
        shutil.copy(source, p(name))
        with h5py.File(p(name), "r+") as f:
            edit(f)
        return p(name)

    def drop(f, path):
        del f[path]

    h5 = open(base, "rb").read()
    write(p("truncated.h5"), h5[: len(h5) // 2])
    c.all_readers("h5_truncated", p("truncated.h5"), ["truncated.h5"])
    write(p("text.h5"), "not an hdf5 file\n")
    c.all_readers("h5_not_hdf5", p("text.h5"), ["text.h5", "not an HDF5 file"])
    c.all_readers("h5_no_signals", variant("no_signals.h5", lambda f: drop(f, "signals")),
                  ["no_signals.h5", "/signals"])

    def empty_signals(f):
        for k in list(f["signals"].keys()):
            del f["signals"][k]
    c.all_readers("h5_empty_signals", variant("empty_signals.h5", empty_signals),
                  ["empty_signals.h5", "no channels"])

    def zero_length(f):
        attrs = dict(f["signals/a"].attrs)
        del f["signals/a"]
        d = f["signals"].create_dataset("a", shape=(0,), dtype="f8")
        for k, v in attrs.items():
            d.attrs[k] = v
    c.all_readers("h5_zero_length", variant("zero_length.h5", zero_length),
                  ["zero_length.h5", "/signals/a", "no samples"])

    def soft_loop(f):
        f["signals"]["loop"] = h5py.SoftLink("/signals/loop")
    c.all_readers("h5_soft_link_loop", variant("soft_loop.h5", soft_loop),
                  ["soft_loop.h5", "soft link"])

    def external(f):
        f["signals"]["ext"] = h5py.ExternalLink("/dev/zero", "/x")
    c.all_readers("h5_external_link", variant("external.h5", external),
                  ["external.h5", "external link"])

    def signals_soft(f):
        f.move("signals", "real_signals")
        f["signals"] = h5py.SoftLink("/real_signals")
    c.import_case("h5_signals_is_soft_link", variant("signals_soft.h5", signals_soft),
                  ["signals_soft.h5", "soft link"])

    def gearbox_not_json(f):
        f.create_dataset("gearbox", data="{not json", dtype=h5py.string_dtype())
    c.all_readers("h5_gearbox_not_json", variant("gearbox_not_json.h5", gearbox_not_json),
                  ["gearbox_not_json.h5", "/gearbox", "not valid JSON"])

    def gearbox_numeric(f):
        f.create_dataset("gearbox", data=np.arange(3.0))
    c.import_case("h5_gearbox_not_string", variant("gearbox_numeric.h5", gearbox_numeric),
                  ["gearbox_numeric.h5", "/gearbox"])

    def rank2(f):
        attrs = dict(f["signals/a"].attrs)
        del f["signals/a"]
        d = f["signals"].create_dataset("a", data=np.ones((4, 5)))
        for k, v in attrs.items():
            d.attrs[k] = v
    c.all_readers("h5_rank2", variant("rank2.h5", rank2), ["rank2.h5", "1-D"])

    def string_channel(f):
        del f["signals/a"]
        f["signals"].create_dataset("a", data="text", dtype=h5py.string_dtype())
    c.import_case("h5_string_channel", variant("string_channel.h5", string_channel),
                  ["string_channel.h5", "numeric"])

    c.all_readers("h5_fs_missing",
                  variant("fs_missing.h5", lambda f: f["signals/a"].attrs.__delitem__("fs_hz")),
                  ["fs_missing.h5", "fs_hz"])

    def fs_negative(f):
        f["signals/a"].attrs["fs_hz"] = -1000.0
    c.import_case("h5_fs_negative", variant("fs_negative.h5", fs_negative),
                  ["fs_negative.h5", "fs_hz"])

    def fs_tiny(f):
        f["signals/a"].attrs["fs_hz"] = 1e-300
    c.all_readers("h5_fs_tiny", variant("fs_tiny.h5", fs_tiny), ["fs_tiny.h5", "fs_hz"])

    def nan_sample(f):
        f["signals/a"][3] = np.nan
    c.all_readers("h5_nan_sample", variant("nan_sample.h5", nan_sample),
                  ["nan_sample.h5", "sample 3", "NaN"], info=False)

    def newer(f):
        f.attrs["format_version"] = np.int32(99)
    c.import_case("h5_newer_format", variant("newer.h5", newer), ["newer.h5", "format_version"])

    def bad_role(f):
        f["signals/a"].attrs["role"] = "banana"
    c.all_readers("h5_bad_role", variant("bad_role.h5", bad_role), ["bad_role.h5", "role"])

    def bad_direction(f):
        f["signals/a"].attrs["direction"] = "sideways"
    c.import_case("h5_bad_direction", variant("bad_direction.h5", bad_direction),
                  ["bad_direction.h5", "direction"])

    def bad_ppr(f):
        f["signals/a"].attrs["ppr"] = np.float64(2.5)
    c.import_case("h5_bad_ppr", variant("bad_ppr.h5", bad_ppr), ["bad_ppr.h5", "ppr"])

    def dims_lie(f):
        attrs = dict(f["signals/a"].attrs)
        del f["signals/a"]
        d = f["signals"].create_dataset("a", shape=(100_000_000,), chunks=(1000,), dtype="f8")
        d[:1000] = 1.0
        for k, v in attrs.items():
            d.attrs[k] = v
    # 1000 of 10^8 declared samples written: the chunks never written are named (the structure
    # check of every HDF5 open comes before the channel's own length check).
    c.all_readers("h5_length_lie", variant("length_lie.h5", dims_lie),
                  ["length_lie.h5", "/signals/a", "99999 of its 100000 chunks were never written"])

    def tacho_without_ppr(f):
        g = f.create_group("tacho")
        d = g.create_dataset("b", data=np.ones(50))
        for k, v in f["signals/b"].attrs.items():
            d.attrs[k] = v
        d.attrs["role"] = "tacho"
        d.attrs["ppr"] = np.int32(0)
    c.import_case("h5_tacho_ppr0", variant("tacho_ppr0.h5", tacho_without_ppr),
                  ["tacho_ppr0.h5", "ppr >= 1"])

    # Byte damage in the raw (uncompressed) file's sample area: refused or read, never a crash.
    # The samples of /signals/a lie where their float64 bytes are.
    blob = bytearray(open(raw, "rb").read())
    first = struct.pack("<d", np.sin(0.1))
    at = blob.find(first)
    if at < 0:
        sys.exit("bad_inputs.py: cannot find the samples in the raw base file")
    blob[at: at + 8] = struct.pack("<d", float("inf"))
    write(p("raw_inf.h5"), bytes(blob))
    c.all_readers("h5_raw_inf_sample", p("raw_inf.h5"), ["raw_inf.h5", "sample 1", "infinite"],
                  info=False)

    # A mutated recording on which the system HDF5 (1.10) itself crashes (SIGSEGV; found by
    # fuzz_hdf5, ASan: memcpy-param-overlap inside libhdf5): the reader's survey child takes the
    # crash and the file is refused.
    crasher = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                           "fuzz", "regressions", "hdf5", "libhdf5_memcpy_overlap.h5")
    shutil.copy(crasher, p("libhdf5_crash.h5"))
    c.all_readers("h5_libhdf5_crash", p("libhdf5_crash.h5"), ["libhdf5_crash.h5", "corrupted file"])

    # Data a recording points at outside itself (docs/limits.md): external storage (a channel
    # whose bytes are another file's: /etc/passwd exported through a report), virtual datasets,
    # chunks never written (read as zeros by HDF5), a raw chunk 8 bytes short.
    secret = p("secret.bin")
    write(secret, np.arange(50, dtype="<f8").tobytes())

    def copy_attrs(src, dst):
        for k, v in src.attrs.items():
            dst.attrs[k] = v

    def external_storage(f):
        attrs = f["signals/a"]
        d = f["signals"].create_dataset("ext", shape=(50,), dtype="<f8",
                                        external=[(secret, 0, 400)])
        copy_attrs(attrs, d)
    c.all_readers("h5_external_storage", variant("external_storage.h5", external_storage),
                  ["external_storage.h5", "/signals/ext", "external files"])

    def virtual(f):
        layout = h5py.VirtualLayout(shape=(50,), dtype="<f8")
        layout[:] = h5py.VirtualSource(base, "/signals/a", shape=(50,))
        d = f["signals"].create_virtual_dataset("virt", layout)
        copy_attrs(f["signals/a"], d)
    c.all_readers("h5_virtual_dataset", variant("virtual.h5", virtual),
                  ["virtual.h5", "/signals/virt", "virtual dataset"])

    def unwritten(f):
        d = f["signals"].create_dataset("holes", shape=(200000,), dtype="<f8", chunks=(10000,),
                                        compression="gzip")
        d[:20000] = 0.5
        copy_attrs(f["signals/a"], d)
    c.all_readers("h5_chunks_never_written", variant("unwritten.h5", unwritten),
                  ["unwritten.h5", "/signals/holes", "18 of its 20 chunks were never written"])

    def short_chunk(f):
        d = f["signals"].create_dataset("short", shape=(2048,), dtype="<f8", chunks=(1024,),
                                        shuffle=True, compression="gzip")
        copy_attrs(f["signals/a"], d)
        raw_chunk = np.full(1024, 0.25, dtype="<f8").tobytes()
        d.id.write_direct_chunk((0,), raw_chunk, filter_mask=0x3)
        d.id.write_direct_chunk((1024,), raw_chunk[:-8], filter_mask=0x3)
    c.all_readers("h5_raw_chunk_short", variant("short_chunk.h5", short_chunk),
                  ["short_chunk.h5", "/signals/short", "chunk at sample 1024"], info=False)

    def escape_unit(f):
        f["signals/a"].attrs["unit"] = "\x1b[2J\x1b[31mg"
    c.all_readers("h5_escape_in_unit", variant("escape_unit.h5", escape_unit),
                  ["escape_unit.h5", "unit", "\\x1b", "control character"])

    # MAT files declaring what they do not hold.
    write(p("v4_wrap.mat"), struct.pack("<5i", 0, 1 << 30, 1 << 30, 1, 2) + b"x\0" + bytes(64))
    c.import_case("mat_v4_dims_wrap", p("v4_wrap.mat"), ["v4_wrap.mat", "1073741824 x 1073741824"],
                  ["--fs", "100"])

    def mat73(name, make):
        path = p(name)
        with h5py.File(path, "w", userblock_size=512) as f:
            make(f)
        header = b"MATLAB 7.3 MAT-file, written by bad_inputs.py".ljust(124, b" ")
        with open(path, "r+b") as f:
            f.write(header + b"\x00\x02IM")
        return path

    def mat73_unwritten(f):
        d = f.create_dataset("x", shape=(100000000, 1), dtype="<f8", chunks=(65536, 1),
                             compression="gzip")
        d.attrs["MATLAB_class"] = np.bytes_("double")
    c.import_case("mat73_unwritten_1e8", mat73("unwritten73.mat", mat73_unwritten),
                  ["unwritten73.mat", "/x", "never written"], ["--fs", "100"])

    def mat73_external(f):
        d = f.create_dataset("x", shape=(50, 1), dtype="<f8", external=[(secret, 0, 400)])
        d.attrs["MATLAB_class"] = np.bytes_("double")
    c.import_case("mat73_external_storage", mat73("external73.mat", mat73_external),
                  ["external73.mat", "/x", "external files"], ["--fs", "100"])
    # A mutation of external73.mat that fuzz_mat made: /x cannot be opened, the file's close then
    # fails and it stays half-open in the HDF5 library, whose exit handler crashed on it (SIGSEGV
    # after the message) until geardiag turned that handler off.
    half_open = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "fuzz",
                             "regressions", "mat", "half_open73.mat")
    c.all_readers("mat73_half_open", half_open, ["half_open73.mat", "/x", "cannot be opened"],
                  ["--fs", "12000"], info=False)

    # ---- face-gear stiffness tables and wear runs ------------------------------------------
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    face_gear = json.load(open(os.path.join(root, "testdata", "gearbox", "seed002_face_gear.json")))

    def face_gear_case(name, table, expect):
        desc = dict(face_gear)
        pair = {k: v for k, v in face_gear["face_gear_pair"].items() if k != "static_te_um"}
        desc["face_gear_pair"] = dict(pair, stiffness_table=table)  # the table gives the TE
        gb = p(name + ".json")
        write(gb, json.dumps(desc))
        out = os.path.join(c.out(name), "fg.h5")
        c.add(name, ["simulate", "--gearbox", gb, "--duration", "0.01", "-o", out], expect, [out])

    header = "flank,angle_deg,load_nm,stiffness_nm_per_rad,e0_urad\n"
    write(p("fg_extra_field.csv"), header + "drive,0,1,1e6,0,7\n")
    face_gear_case("facegear_csv_extra_field", "fg_extra_field.csv",
                   ["fg_extra_field.csv", "line 2", "exactly 5"])
    write(p("fg_secret.csv"), "root:SECRET-TEXT:0:0\n")
    face_gear_case("facegear_csv_no_echo", "fg_secret.csv", ["fg_secret.csv", "header"])
    fg_fifo = p("fg_fifo.csv")
    if os.path.exists(fg_fifo):
        os.remove(fg_fifo)
    os.mkfifo(fg_fifo)
    face_gear_case("facegear_csv_fifo", "fg_fifo.csv", ["fg_fifo.csv", "FIFO"])

    pair = os.path.join(root, "testdata", "gearbox", "single_stage_29_47.json")
    for name, extra, expect in [("wear_cycles_1e300", ["--cycles", "1e300"], ["cycles"]),
                                ("wear_torque_1e300", ["--cycles", "1e6", "--torque", "1e300"],
                                 ["torque"])]:
        out = os.path.join(c.out(name), "w.h5")
        c.add(name, ["wear", "--gearbox", pair, "--mesh", "pinion_wheel", "--steps", "3",
                     *extra, "-o", out], expect, [out])

    # ---- full disks: every output kind --------------------------------------------------------
    # The run may write 512 bytes (SIGXFSZ ignored: a longer write fails with EFBIG, as ENOSPC on
    # a full disk); a previous file at the output path must come out unchanged.
    def disk_full(name, argv_of, file_name):
        d = c.out(name)
        out = os.path.join(d, file_name)
        write(out, "previous output\n")
        c.add(name, argv_of(out), [file_name, "write failed"], [out], fsize=512, keep=out)

    big_csv = p("big.csv")
    write(big_csv, "time,a\n" + "".join(f"{i / 1000:.6f},{np.sin(1.7 * i) * np.cos(0.31 * i * i):.17g}\n"
                                        for i in range(20000)))
    disk_full("disk_full_import", lambda o: ["import", big_csv, "-o", o], "full.h5")
    disk_full("disk_full_simulate", lambda o: ["simulate", "--gearbox", pair, "--duration", "0.5",
                                               "-o", o], "sim.h5")
    disk_full("disk_full_analyze_json", lambda o: ["analyze", big_csv, "--json", o], "a.json")
    disk_full("disk_full_analyze_html", lambda o: ["analyze", big_csv, "--html", o], "a.html")
    disk_full("disk_full_analyze_curves", lambda o: ["analyze", big_csv, "--curves", o], "c.h5")
    disk_full("disk_full_wear", lambda o: ["wear", "--gearbox", pair, "--mesh", "pinion_wheel",
                                           "--cycles", "1e6", "--steps", "40", "-o", o], "w.h5")

    # ---- special files --------------------------------------------------------------------
    fifo = p("fifo.csv")
    if os.path.exists(fifo):
        os.remove(fifo)
    os.mkfifo(fifo)
    c.all_readers("fifo_no_writer", fifo, ["fifo.csv", "FIFO"])
    link = p("zero.csv")
    if os.path.lexists(link):
        os.remove(link)
    os.symlink("/dev/zero", link)
    c.all_readers("dev_zero_via_link", link, ["zero.csv", "device"])
    link_h5 = p("zero.h5")
    if os.path.lexists(link_h5):
        os.remove(link_h5)
    os.symlink("/dev/zero", link_h5)
    c.import_case("dev_zero_h5", link_h5, ["zero.h5", "device"])
    os.makedirs(p("dir.csv"), exist_ok=True)
    c.import_case("input_is_directory", p("dir.csv"), ["dir.csv", "directory"])
    c.import_case("input_missing", p("missing.csv"), ["missing.csv", "no such file"])

    # ---- channel maps ---------------------------------------------------------------------
    write(p("map_not_json.json"), "{channels: [")
    c.import_case("channel_map_not_json", p("good.csv"), ["map_not_json.json", "not valid JSON"],
                  ["--channels", p("map_not_json.json")])
    write(p("map_empty.json"), b"")
    c.import_case("channel_map_empty", p("good.csv"), ["map_empty.json", "empty file"],
                  ["--channels", p("map_empty.json")])
    c.import_case("channel_map_fifo", p("good.csv"), ["fifo.csv", "FIFO"], ["--channels", fifo])
    c.import_case("channel_map_dev_zero", p("good.csv"), ["zero.csv", "device"],
                  ["--channels", link])
    write(p("map_nul.json"), b'{"channels": []}\0')
    c.import_case("channel_map_nul", p("good.csv"), ["map_nul.json", "NUL byte"],
                  ["--channels", p("map_nul.json")])

    # ---- output paths ---------------------------------------------------------------------
    d = c.out("output_is_directory")
    c.add("output_is_directory", ["import", p("good.csv"), "-o", d], [d, "directory"])
    missing = os.path.join(c.out("output_missing_dir"), "no", "such", "dir", "x.h5")
    c.add("output_missing_dir", ["import", p("good.csv"), "-o", missing], ["does not exist"],
          [missing])
    c.add("output_is_input", ["import", p("good.csv"), "-o", p("good.csv")],
          ["overwrite the input"])
    js = os.path.join(c.out("analyze_json_missing_dir"), "nodir", "a.json")
    c.add("analyze_json_missing_dir", ["analyze", base, "--json", js], ["--json", "does not exist"],
          [js])
    html = c.out("analyze_html_directory")
    c.add("analyze_html_directory", ["analyze", base, "--html", html], ["--html", "directory"])


def limited(fsize):
    """A preexec_fn making the disk full at fsize bytes for the child."""
    def apply():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (fsize, fsize))
    return apply


def run(c, name_filter):
    failures = 0
    ran = 0
    for name, argv, expect, outputs, opts in c.cases:
        if name_filter and name_filter not in name:
            continue
        ran += 1
        out_dirs = {os.path.dirname(o) for o in outputs}
        before = {d: set(os.listdir(d)) if os.path.isdir(d) else set() for d in out_dirs}
        kept = open(opts["keep"], "rb").read() if opts["keep"] else None
        env = dict(os.environ, **opts["env"]) if opts["env"] else None
        start = time.monotonic()
        try:
            r = subprocess.run([c.binary, *argv], capture_output=True, timeout=TIME_LIMIT_S,
                               stdin=subprocess.DEVNULL, env=env,
                               preexec_fn=limited(opts["fsize"]) if opts["fsize"] else None)
            code, err = r.returncode, r.stderr.decode(errors="replace")
        except subprocess.TimeoutExpired:
            code, err = "timeout", ""
        took = time.monotonic() - start
        problems = []
        if code != 2:
            problems.append(f"exit {code}, expected 2")
        for e in expect:
            if e not in err:
                problems.append(f"message lacks {e!r}")
        for d in out_dirs:
            after = set(os.listdir(d)) if os.path.isdir(d) else set()
            if after - before[d]:
                problems.append(f"left {sorted(after - before[d])} in {d}")
        if kept is not None and open(opts["keep"], "rb").read() != kept:
            problems.append(f"the previous {opts['keep']} was changed")
        if problems:
            failures += 1
            print(f"FAIL {name} ({took:.2f} s): {'; '.join(problems)}\n     stderr: {err.strip()}")
        else:
            print(f"ok   {name} ({took:.2f} s): {err.strip().splitlines()[-1] if err.strip() else ''}")
    print(f"bad_inputs.py: {ran - failures} of {ran} cases passed")
    return failures == 0 and ran > 0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--geardiag", required=True)
    ap.add_argument("--dir", required=True)
    ap.add_argument("--generate-only", action="store_true")
    ap.add_argument("--filter", default="")
    args = ap.parse_args()
    root = os.path.abspath(args.dir)
    shutil.rmtree(os.path.join(root, "out"), ignore_errors=True)
    c = Corpus(os.path.abspath(args.geardiag), root)
    generate(c)
    if args.generate_only:
        print(f"bad_inputs.py: {len(c.cases)} cases in {root}")
        return 0
    return 0 if run(c, args.filter) else 1


if __name__ == "__main__":
    sys.exit(main())
