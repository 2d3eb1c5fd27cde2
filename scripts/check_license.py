#!/usr/bin/env python3
"""Checks that vislib states one license everywhere it is stated (ctest License.*).

    check_license.py [ROOT]              exit 0 when all of these hold, 1 with one line per failure:
      - LICENSE is the Apache License 2.0, verbatim (byte-identical to Debian's
        /usr/share/common-licenses/Apache-2.0 where that file exists, else its first and last lines);
      - CMakeLists.txt's `set(VISLIB_LICENSE ...)` names it (SPDX: Apache-2.0);
      - web/package.json's "license" and the root package of web/package-lock.json say the same;
      - README.md names the license and links LICENSE;
      - web/THIRD_PARTY.md lists every package the web page ships (the non-development packages of
        web/package-lock.json) with its locked version and the license the lock file records.
    check_license.py --self-test [ROOT]  copies those files, breaks them one at a time and passes only
                                         if the check rejects every broken copy.
Standard library only.
"""
import json
import pathlib
import re
import shutil
import sys
import tempfile

SPDX = "Apache-2.0"
DEBIAN_TEXT = pathlib.Path("/usr/share/common-licenses/Apache-2.0")
FILES = ["LICENSE", "CMakeLists.txt", "README.md", "web/package.json", "web/package-lock.json",
         "web/THIRD_PARTY.md"]


def read(root, rel, errors):
    path = root / rel
    if not path.is_file():
        errors.append(f"{rel}: missing")
        return None
    return path.read_text(encoding="utf-8")


def check_license_text(root, errors):
    text = read(root, "LICENSE", errors)
    if text is None:
        return
    if DEBIAN_TEXT.is_file():
        if text != DEBIAN_TEXT.read_text(encoding="utf-8"):
            errors.append(f"LICENSE: differs from {DEBIAN_TEXT} (the Apache License 2.0, verbatim)")
        return
    lines = [line.strip() for line in text.splitlines() if line.strip()]
    if lines[:2] != ["Apache License", "Version 2.0, January 2004"] or \
            "END OF TERMS AND CONDITIONS" not in lines:
        errors.append("LICENSE: not the Apache License 2.0 text")


def check_cmake(root, errors):
    text = read(root, "CMakeLists.txt", errors)
    if text is None:
        return
    m = re.search(r"^set\(VISLIB_LICENSE\s+(\S+)\)", text, re.M)
    if not m:
        errors.append("CMakeLists.txt: no set(VISLIB_LICENSE ...)")
    elif m.group(1) != SPDX:
        errors.append(f"CMakeLists.txt: VISLIB_LICENSE is {m.group(1)}, LICENSE is {SPDX}")


def load_json(root, rel, errors):
    text = read(root, rel, errors)
    if text is None:
        return None
    try:
        return json.loads(text)
    except json.JSONDecodeError as e:
        errors.append(f"{rel}: not JSON ({e})")
        return None


def check_web(root, errors):
    package = load_json(root, "web/package.json", errors)
    lock = load_json(root, "web/package-lock.json", errors)
    if package is not None and package.get("license") != SPDX:
        errors.append(f"web/package.json: license is {package.get('license')!r}, LICENSE is {SPDX}")
    if lock is None:
        return
    packages = lock.get("packages", {})
    if packages.get("", {}).get("license") != SPDX:
        errors.append(f"web/package-lock.json: the root package's license is "
                      f"{packages.get('', {}).get('license')!r}, LICENSE is {SPDX}")
    notices = read(root, "web/THIRD_PARTY.md", errors)
    if notices is None:
        return
    for key, entry in sorted(packages.items()):
        if not key.startswith("node_modules/") or entry.get("dev"):
            continue
        name = key[len("node_modules/"):]
        heading = re.search(rf"^## .*\b{re.escape(name.split('/')[-1])}\S* {re.escape(entry['version'])}\b",
                            notices, re.M | re.I)
        if not heading:
            errors.append(f"web/THIRD_PARTY.md: no section for {name} {entry['version']} "
                          f"(shipped by the page, web/package-lock.json)")
        elif entry.get("license") and entry["license"] not in notices[heading.end():].split("\n## ")[0]:
            errors.append(f"web/THIRD_PARTY.md: the section of {name} does not name its license "
                          f"{entry['license']}")


def check_readme(root, errors):
    text = read(root, "README.md", errors)
    if text is not None and (SPDX not in text or "(LICENSE)" not in text):
        errors.append(f"README.md: does not name the license ({SPDX}) and link LICENSE")


def check(root):
    errors = []
    for step in (check_license_text, check_cmake, check_web, check_readme):
        step(root, errors)
    return errors


def self_test(root):
    breaks = {
        "no LICENSE": lambda d: (d / "LICENSE").unlink(),
        "another LICENSE text": lambda d: (d / "LICENSE").write_text("MIT License\n"),
        "LICENSE edited": lambda d: (d / "LICENSE").write_text(
            (d / "LICENSE").read_text().replace("Version 2.0", "Version 2.1")),
        "CMake license changed": lambda d: sub(d / "CMakeLists.txt", r"set\(VISLIB_LICENSE \S+\)",
                                               "set(VISLIB_LICENSE MIT)"),
        "package.json UNLICENSED": lambda d: sub(d / "web/package.json", r'"license": "[^"]*"',
                                                 '"license": "UNLICENSED"'),
        "package.json without license": lambda d: sub(d / "web/package.json", r'\s*"license": "[^"]*",', ""),
        "lock root disagrees": lambda d: sub(d / "web/package-lock.json", r'"license": "[^"]*"',
                                             '"license": "UNLICENSED"', count=1),
        "three upgraded, notices not": lambda d: sub(d / "web/package-lock.json",
                                                     r'("node_modules/three": \{\s*"version": ")[^"]*',
                                                     r"\g<1>9.9.9"),
        "README silent": lambda d: sub(d / "README.md", re.escape(SPDX), "?"),
    }
    failures = 0
    for name, breaker in breaks.items():
        with tempfile.TemporaryDirectory() as tmp:
            copy = pathlib.Path(tmp)
            for rel in FILES:
                (copy / rel).parent.mkdir(parents=True, exist_ok=True)
                shutil.copy(root / rel, copy / rel)
            if check(copy):
                print(f"self-test: the intact copy fails: {check(copy)}")
                return 1
            breaker(copy)
            if not check(copy):
                print(f"self-test: not rejected: {name}")
                failures += 1
    print(f"self-test: {len(breaks) - failures} of {len(breaks)} broken copies rejected")
    return 1 if failures else 0


def sub(path, pattern, repl, count=0):
    text = path.read_text(encoding="utf-8")
    new = re.sub(pattern, repl, text, count=count)
    assert new != text, f"self-test: {pattern} not found in {path}"
    path.write_text(new, encoding="utf-8")


def main(argv):
    selftest = "--self-test" in argv
    args = [a for a in argv if a != "--self-test"]
    root = pathlib.Path(args[0] if args else pathlib.Path(__file__).resolve().parent.parent)
    if selftest:
        return self_test(root)
    errors = check(root)
    for e in errors:
        print(f"check_license: {e}")
    if not errors:
        print(f"check_license: LICENSE, CMakeLists.txt, README.md and web/ agree on {SPDX}")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
