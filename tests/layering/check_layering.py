#!/usr/bin/python3
"""Checks the modules' include direction and the installed headers.

1. A module's sources (src/<module>/**) include only its own headers and those of the
   modules its CMake target links (src/<module>/CMakeLists.txt, clumpforge::<other>, followed
   transitively): never a module above it.
2. The installed headers (src/<module>/include/clumpforge/*.hpp, include/clumpforge/*.hpp)
   include the standard library and other installed headers only: no third-party type.

    check_layering.py SOURCE_ROOT       exit 1 and one line per violation
    check_layering.py --self-test       proves the check fails on an upward include
"""
import pathlib
import re
import sys
import tempfile

INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]', re.M)
LINK = re.compile(r"clumpforge::(\w+)")
STD_HEADERS = {
    "algorithm", "array", "cmath", "cstddef", "cstdint", "expected", "filesystem", "functional", "map",
    "memory", "optional", "span", "string", "string_view", "utility", "vector",
}


def modules(root):
    src = root / "src"
    return sorted(p.name for p in src.iterdir() if (p / "CMakeLists.txt").exists())


def links(root, module):
    text = (root / "src" / module / "CMakeLists.txt").read_text()
    return {m for m in LINK.findall(text) if m != module}


def allowed(root, module, names):
    seen, todo = {module}, [module]
    while todo:
        for other in links(root, todo.pop()):
            if other in names and other not in seen:
                seen.add(other)
                todo.append(other)
    return seen


def sources(directory):
    return [p for p in directory.rglob("*") if p.suffix in (".hpp", ".cpp", ".h")]


def check(root):
    root = pathlib.Path(root)
    names = modules(root)
    problems = []
    for module in names:
        ok = allowed(root, module, names)
        for path in sources(root / "src" / module):
            for _, target in INCLUDE.findall(path.read_text()):
                first = target.split("/")[0]
                if "/" in target and first in names and first not in ok:
                    problems.append(f"{path.relative_to(root)}: includes {target}, but {module} does not link {first} "
                                    f"(it may use: {', '.join(sorted(ok))})")
    public = list((root / "include").rglob("*.hpp")) + [p for m in names for p in (root / "src" / m / "include").rglob("*.hpp")]
    for path in public:
        for bracket, target in INCLUDE.findall(path.read_text()):
            if target.startswith("clumpforge/"):
                continue
            if bracket == "<" and target in STD_HEADERS:
                continue
            problems.append(f"{path.relative_to(root)}: an installed header includes {target} (standard library and "
                            f"clumpforge/ headers only)")
    return problems


def self_test():
    with tempfile.TemporaryDirectory() as tmp:
        root = pathlib.Path(tmp)
        for module, linked in (("core", ""), ("mesh", "clumpforge::core"), ("fill", "clumpforge::mesh")):
            (root / "src" / module / "include" / "clumpforge").mkdir(parents=True)
            (root / "src" / module / "CMakeLists.txt").write_text(f"target_link_libraries(x PUBLIC {linked})\n")
        (root / "include").mkdir()
        (root / "src" / "fill" / "a.cpp").write_text('#include "mesh/x.hpp"\n#include "core/y.hpp"\n')
        if check(root):
            return ["the check refused a downward include"]
        (root / "src" / "mesh" / "b.cpp").write_text('#include "fill/z.hpp"\n')
        (root / "src" / "mesh" / "include" / "clumpforge" / "mesh.hpp").write_text("#include <Eigen/Core>\n")
        found = check(root)
        if len(found) != 2 or "includes fill/z.hpp" not in found[0] or "Eigen/Core" not in found[1]:
            return ["the check missed an upward include or a third-party installed include: " + repr(found)]
    return []


def main():
    problems = self_test() if sys.argv[1:] == ["--self-test"] else check(sys.argv[1])
    for p in problems:
        print(p)
    if not problems:
        print("layering: ok")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
