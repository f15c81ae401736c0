#!/usr/bin/env python3
"""Checks that the README's test command builds nothing the README does not ask for.

The README names a Rust toolchain and a C compiler. The packages that `cargo test --release`
builds (the workspace's default members with their normal, build and dev dependencies, as
`cargo tree` resolves them for this machine) may therefore link no system library: no
package may declare a `links` key outside ALLOWED_LINKS, and none of the crates through
which a build script finds or builds a system library with other tools (pkg-config,
system-deps, vcpkg, cmake, bindgen) may be in the graph. METIS is built from its vendored
source with the C compiler, which needs metis-sys's `vendored` feature.

Usage: .ci/readme-deps.py [PACKAGE SELECTION]   (from the repository's root; exit 1 naming
what is wrong). A selection such as `--workspace` or `-p adhesim-fclib` is handed to
`cargo tree` in place of the default members (`--workspace` fails: it takes in the HDF5 reader
and the Python module).
"""

from __future__ import annotations

import json
import subprocess
import sys

# `links` keys that name no system library: rayon-core's marker keeps one copy of its
# global thread pool in a build, and wasm-bindgen's is for WebAssembly targets only.
ALLOWED_LINKS = {"rayon-core", "wasm_bindgen"}
# Crates a build script uses to find a system library or to build one with a tool that the
# README does not name.
SYSTEM_FINDERS = {"pkg-config", "system-deps", "vcpkg", "cmake", "bindgen"}


def cargo(*args: str) -> str:
    return subprocess.run(
        ["cargo", *args], check=True, capture_output=True, text=True
    ).stdout


def graph(selection: list[str]) -> dict[str, set[str]]:
    """The packages of the selected build and its tests (default: the default members):
    name -> active features."""
    out = cargo(
        "tree", "--locked", *selection, "-e", "normal,build,dev", "--prefix", "none",
        "-f", "{p}|{f}",
    )
    packages: dict[str, set[str]] = {}
    for line in out.splitlines():
        if "|" not in line:
            continue
        package, features = line.split("|", 1)
        name = package.split()[0]
        features = features.split(" (*)")[0]
        packages.setdefault(name, set()).update(f for f in features.split(",") if f)
    return packages


def links_by_name() -> dict[str, str]:
    meta = json.loads(cargo("metadata", "--format-version", "1", "--locked"))
    return {p["name"]: p["links"] for p in meta["packages"] if p.get("links")}


def problems(packages: dict[str, set[str]], links: dict[str, str]) -> list[str]:
    found = []
    for name in sorted(packages):
        if name in links and links[name] not in ALLOWED_LINKS:
            found.append(f"{name} links the system library `{links[name]}`")
        if name in SYSTEM_FINDERS:
            found.append(f"{name} is in the graph (a build script looks for a system library)")
    if "metis-sys" in packages and "vendored" not in packages["metis-sys"]:
        found.append("metis-sys is built without its `vendored` feature (it would link METIS)")
    if "metis-sys" not in packages:
        found.append("metis-sys is not in the graph: this check no longer sees the build")
    return found


def main(selection: list[str]) -> int:
    packages = graph(selection)
    found = problems(packages, links_by_name())
    if found:
        print(
            "readme-deps: the README's test command needs more than a Rust toolchain and "
            "a C compiler:",
            file=sys.stderr,
        )
        for p in found:
            print(f"  - {p}", file=sys.stderr)
        return 1
    print(f"readme-deps: {len(packages)} packages, none links a system library")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
