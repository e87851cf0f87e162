"""Checks shared by the output-folder tests (tests/cli_outputs.cmake): whether an
image file is whole, and whether a `run` output folder is coherent
(docs/results.md#output-folders). Standard library only: PNG is decoded with
zlib, an OpenEXR file is checked through its header and chunk offset table."""
import json
import os
import struct
import zlib

# The images `run` writes for the scene the tests use (scenes/ci-small.json):
# frames at render.width x render.height with 3 channels, top views at
# grid nx x ny with one channel (docs/results.md).
FRAME_SIZE = (160, 120)
TOPVIEW_SIZE = (64, 64)


def expected_size(name):
    base = os.path.basename(name)
    if base.startswith("frame-"):
        return FRAME_SIZE
    if base.startswith("topview-"):
        return TOPVIEW_SIZE
    return None


def png_problem(path, size):
    """None when `path` is a whole PNG of `size` (width, height), else why not."""
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        return "not a PNG signature"
    at, idat, header, ended = 8, b"", None, False
    while at + 12 <= len(data):
        (length,) = struct.unpack(">I", data[at:at + 4])
        kind = data[at + 4:at + 8]
        body = data[at + 8:at + 8 + length]
        if at + 12 + length > len(data):
            return "chunk %r runs past the end" % kind
        (crc,) = struct.unpack(">I", data[at + 8 + length:at + 12 + length])
        if zlib.crc32(kind + body) != crc:
            return "chunk %r has a bad CRC" % kind
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        elif kind == b"IEND":
            ended = True
            break
        at += 12 + length
    if header is None or not ended:
        return "no IHDR or no IEND"
    width, height, depth, colour = header[:4]
    if size and (width, height) != size:
        return "size %dx%d, expected %dx%d" % (width, height, size[0], size[1])
    channels = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}[colour]
    try:
        pixels = zlib.decompress(idat)
    except zlib.error as e:
        return "IDAT does not decompress: %s" % e
    row = 1 + (width * channels * depth + 7) // 8
    if len(pixels) != height * row:
        return "%d pixel bytes, expected %d" % (len(pixels), height * row)
    return None


EXR_LINES_PER_CHUNK = {0: 1, 1: 1, 2: 1, 3: 16, 4: 32, 5: 16, 6: 32, 7: 32, 8: 32, 9: 256}


def exr_problem(path, size):
    """None when `path` is a whole scanline OpenEXR file of `size`, else why not."""
    data = open(path, "rb").read()
    if data[:4] != b"\x76\x2f\x31\x01":
        return "not an OpenEXR magic number"
    (version,) = struct.unpack("<I", data[4:8])
    if version & 0x1200:
        return "tiled or multi-part files are not checked here"
    at, attributes = 8, {}
    while True:
        end = data.find(b"\0", at)
        if end < 0:
            return "header runs past the end"
        name = data[at:end]
        at = end + 1
        if not name:
            break
        end = data.find(b"\0", at)
        if end < 0 or end + 5 > len(data):
            return "header runs past the end"
        (length,) = struct.unpack("<i", data[end + 1:end + 5])
        attributes[name] = data[end + 5:end + 5 + length]
        at = end + 5 + length
    if b"dataWindow" not in attributes or b"compression" not in attributes:
        return "no dataWindow or compression"
    x0, y0, x1, y1 = struct.unpack("<iiii", attributes[b"dataWindow"])
    width, height = x1 - x0 + 1, y1 - y0 + 1
    if size and (width, height) != size:
        return "size %dx%d, expected %dx%d" % (width, height, size[0], size[1])
    lines = EXR_LINES_PER_CHUNK.get(attributes[b"compression"][0])
    if lines is None:
        return "unknown compression"
    chunks = (height + lines - 1) // lines
    if at + 8 * chunks > len(data):
        return "offset table runs past the end"
    offsets = struct.unpack("<%dQ" % chunks, data[at:at + 8 * chunks])
    for n, offset in enumerate(offsets):
        if offset + 8 > len(data):
            return "chunk %d starts past the end" % n
        y, length = struct.unpack("<ii", data[offset:offset + 8])
        if y != y0 + n * lines or offset + 8 + length > len(data):
            return "chunk %d is cut short or misplaced" % n
    return None


def image_problem(path):
    size = expected_size(path)
    if path.endswith(".png"):
        return png_problem(path, size)
    if path.endswith(".exr"):
        return exr_problem(path, size)
    return None


def visible_files(folder):
    """Every file under `folder` whose name does not start with '.', relative, with its identity:
    inode, change and modification times and size (an inode number alone is reused at once)."""
    found = {}
    for root, dirs, files in os.walk(folder):
        dirs[:] = [d for d in dirs if not d.startswith(".")]
        for name in files:
            if not name.startswith("."):
                path = os.path.join(root, name)
                info = os.lstat(path)
                found[os.path.relpath(path, folder)] = (info.st_ino, info.st_ctime_ns, info.st_mtime_ns,
                                                        info.st_size)
    return found


def temporary_files(folder):
    """The temporary names of writes cut short (".<stem>.partial<ext>"), relative."""
    found = []
    for root, dirs, files in os.walk(folder):
        found += [os.path.relpath(os.path.join(root, n), folder) for n in files
                  if n.startswith(".") and ".partial" in n]
    return sorted(found)


def results_problems(folder):
    """Why results.json in `folder` is not whole or names a file that is not whole: [] when it is
    absent, or valid JSON whose "files" all exist and are whole images."""
    path = os.path.join(folder, "results.json")
    if not os.path.exists(path):
        return []
    try:
        doc = json.load(open(path))
    except ValueError as e:
        return ["results.json is not valid JSON: %s" % e]
    problems = []
    for name in doc.get("files", []):
        full = os.path.join(folder, name)
        if not os.path.isfile(full):
            problems.append("results.json names %s, which does not exist" % name)
        elif image_problem(full):
            problems.append("%s: %s" % (name, image_problem(full)))
    if "files" not in doc:
        problems.append('results.json has no "files"')
    return problems


def complete_run_problems(folder):
    """Why `folder` does not hold exactly one complete run: results.json complete, listing every
    visible file besides itself, each whole, and no temporary file."""
    problems = results_problems(folder)
    path = os.path.join(folder, "results.json")
    if not os.path.exists(path):
        return problems + ["no results.json"]
    doc = json.load(open(path))
    if doc.get("complete") is not True:
        problems.append("results.json is not complete")
    unlisted = sorted(set(visible_files(folder)) - set(doc.get("files", [])) - {"results.json"})
    if unlisted:
        problems.append("files results.json does not list: %s" % ", ".join(unlisted))
    if temporary_files(folder):
        problems.append("temporary files left: %s" % ", ".join(temporary_files(folder)))
    return problems
