#!/usr/bin/env python3
"""Picks a sample of fuzz-corpus inputs that blender2ogl accepts, as plain model files.

Usage: make_sample.py BLENDER2OGL CORPUS_DIR OUT_DIR [COUNT]
A fuzz input is one option byte, the .obj text, and optionally "%%MTL\\n" + the .mtl text (see
fuzz/fuzz_converter.cpp). Each accepted one becomes sNN.obj (+ sNN.mtl) and sNN.args (the
command-line options that the option byte stands for). The test accepted_compile_test.cpp
converts them all and compiles the generated code in one batch.
"""
import os, re, subprocess, sys, tempfile, shutil

exe, corpus, out = sys.argv[1], sys.argv[2], sys.argv[3]
count = int(sys.argv[4]) if len(sys.argv) > 4 else 20
files = sorted(os.listdir(corpus), key=lambda f: (os.path.getsize(os.path.join(corpus, f)), f))
picked, seen_sizes = [], set()
with tempfile.TemporaryDirectory() as tmp:
    open(os.path.join(tmp, "tex.png"), "wb").write(b"\x89PNG\r\n\x1a\n-not-really-")
    for f in files:
        data = open(os.path.join(corpus, f), "rb").read()
        if len(data) < 2 or len(data) // 64 in seen_sizes:
            continue  # one per size band, for variety
        flags, body = data[0], data[1:]
        obj, _, mtl = body.partition(b"%%MTL\n")
        n = len(picked)
        stem = "s%02d" % n
        obj = obj.replace(b"mtllib in.mtl", b"mtllib " + stem.encode() + b".mtl")
        op, mp = os.path.join(tmp, stem + ".obj"), os.path.join(tmp, stem + ".mtl")
        open(op, "wb").write(obj)
        if b"%%MTL\n" in body:
            open(mp, "wb").write(mtl)
        elif os.path.exists(mp):
            os.remove(mp)
        args = (["-m"] if flags & 1 else []) + (["-r"] if flags & 2 else []) + (["-c"] if flags & 32 else [])
        if flags & 12:  # cloth objects: ask the converter for the object names
            r = subprocess.run([exe, "-a", "no object has this name", "-t", tmp + "/o", op], capture_output=True, text=True, errors="replace")
            m = re.search(r"objects: (.*)$", r.stderr.strip())
            names = re.findall(r"'([^']*)'", m.group(1)) if m else []
            for name in (names if flags & 4 else names[:1]):
                if name and not name.startswith("-"):
                    args += ["-a", name]
        r = subprocess.run([exe, *args, "-t", os.path.join(tmp, "o"), op], capture_output=True)
        if r.returncode != 0:
            continue
        seen_sizes.add(len(data) // 64)
        shutil.copy(op, os.path.join(out, stem + ".obj"))
        if os.path.exists(mp):
            shutil.copy(mp, os.path.join(out, stem + ".mtl"))
        open(os.path.join(out, stem + ".args"), "w").write("\n".join(args) + ("\n" if args else ""))
        picked.append(f)
        if len(picked) == count:
            break
print("picked %d accepted inputs" % len(picked))
