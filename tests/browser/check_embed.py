#!/usr/bin/env python3
"""Checks server/ui/embed_ui.cmake: the generated table compiles (with
server/ui/ui_assets.hpp) and holds every dashboard file and example spec
byte for byte, with the right content type, and find_asset finds them.

    python3 tests/browser/check_embed.py        # needs cmake and a C++20 compiler

Exit 0 when everything matches; otherwise every difference on stderr.
"""

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
TYPES = {".html": "text/html; charset=utf-8", ".css": "text/css; charset=utf-8",
         ".js": "text/javascript; charset=utf-8", ".json": "application/json"}

DUMP = r"""
#include <cstdio>
#include <string>
#include "ui_assets.hpp"
// Writes each asset to argv[1]/<index>, and "path<TAB>type<TAB>index" lines to stdout.
int main(int, char** argv) {
  using hmpm::server::ui::find_asset;
  for (std::size_t i = 0; i < hmpm::server::ui::asset_count; ++i) {
    const auto& a = hmpm::server::ui::assets[i];
    if (find_asset(a.path) != &a) return 2;
    const std::string name = std::string(argv[1]) + "/" + std::to_string(i);
    std::FILE* f = std::fopen(name.c_str(), "wb");
    std::fwrite(a.body.data(), 1, a.body.size(), f);
    std::fclose(f);
    std::printf("%.*s\t%.*s\t%zu\n", int(a.path.size()), a.path.data(), int(a.content_type.size()),
                a.content_type.data(), i);
  }
  return find_asset("/ui/nope.js") == nullptr ? 0 : 3;
}
"""


def main():
    problems = []
    with tempfile.TemporaryDirectory(prefix="hmpm-embed-") as tmp:
        tmp = Path(tmp)
        subprocess.run(["cmake", f"-DUI_DIR={REPO}/server/ui", f"-DEXAMPLES_DIR={REPO}/examples",
                        f"-DOUT={tmp}/ui_assets.cpp", "-P", str(REPO / "server/ui/embed_ui.cmake")], check=True)
        (tmp / "dump.cpp").write_text(DUMP)
        cxx = os.environ.get("CXX", "c++")
        subprocess.run([cxx, "-std=c++20", "-O0", "-Wall", "-Wextra", "-Werror", f"-I{REPO}/server/ui",
                        str(tmp / "dump.cpp"), str(tmp / "ui_assets.cpp"), "-o", str(tmp / "dump")], check=True)
        (tmp / "out").mkdir()
        run = subprocess.run([str(tmp / "dump"), str(tmp / "out")], capture_output=True, text=True)
        if run.returncode != 0:
            problems.append(f"dump exited {run.returncode} (find_asset)")
        got = {}
        for line in run.stdout.splitlines():
            path, kind, index = line.split("\t")
            got[path] = (kind, (tmp / "out" / index).read_bytes())
    expected = {}
    for f in sorted((REPO / "server/ui").iterdir()):
        if f.suffix in (".html", ".css", ".js"):
            expected[f"/ui/{f.name}"] = (TYPES[f.suffix], f.read_bytes())
    names = []
    for f in sorted((REPO / "examples").glob("*.json")):
        expected[f"/ui/examples/{f.name}"] = (TYPES[".json"], f.read_bytes())
        names.append(f.stem)
    for path, (kind, body) in expected.items():
        if path not in got:
            problems.append(f"{path}: missing")
        elif got[path] != (kind, body):
            problems.append(f"{path}: differs (type {got[path][0]!r})")
    index = got.get("/ui/examples/index.json")
    if not index or json.loads(index[1]) != names:
        problems.append(f"/ui/examples/index.json: {index and index[1]!r}, expected {names}")
    extra = set(got) - set(expected) - {"/ui/examples/index.json"}
    if extra:
        problems.append(f"unexpected assets: {sorted(extra)}")
    for p in problems:
        print(f"check_embed: {p}", file=sys.stderr)
    print(f"check_embed: {len(got)} assets, {'OK' if not problems else f'{len(problems)} problem(s)'}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
