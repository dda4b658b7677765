#!/usr/bin/env python3
"""The container's runtime stage installs every Debian library facet and facetd load.

deploy/Containerfile builds in one stage and runs in another that installs only the runtime
packages it names; a library the binaries link that no named package (or a package they pull in)
provides makes facetd fail at start inside the container, which nothing else here would notice.
For each binary: ldd's libraries -> their Debian packages (dpkg -S) -> each must be named in the
runtime stage or be among the dependencies of those named (apt-cache depends, recursively).

A BINARY without a slash is a library the binaries load by its soname at run time (dlopen, as
libpq.so.5): found through ldconfig's cache, it is checked itself beside the libraries it loads.

Usage: container_runtime_libraries.py SOURCE_DIR BINARY...
"""
import re
import subprocess
import sys

source, binaries = sys.argv[1], sys.argv[2:]
with open(f"{source}/deploy/Containerfile") as f:
    text = f.read()
# The runtime stage: after the last FROM, the packages of its apt-get install.
runtime = text[text.rindex("\nFROM "):]
install = re.search(r"apt-get install -y --no-install-recommends(.*?)&&", runtime, re.S)
if not install:
    sys.exit("deploy/Containerfile: no apt-get install in the runtime stage")
named = install.group(1).replace("\\", " ").split()
deps = subprocess.run(
    ["apt-cache", "depends", "--recurse", "--no-recommends", "--no-suggests", "--no-conflicts",
     "--no-breaks", "--no-replaces", "--no-enhances", *named],
    capture_output=True, text=True, check=True).stdout
provided = set(named) | {line.strip() for line in deps.splitlines() if not line.startswith(" ")}

# Every library of every binary, then one dpkg query for all of them (each query reads dpkg's
# whole database). /lib is a link to /usr/lib on Debian 12: dpkg knows a file by one of the two.
users = {}
cache = None
for i, binary in enumerate(binaries):
    if "/" not in binary:
        if cache is None:
            cache = subprocess.run(["ldconfig", "-p"], capture_output=True, text=True,
                                   check=True).stdout
        found = re.search(rf"^\s*{re.escape(binary)} \(.*\) => (\S+)$", cache, re.M)
        if not found:
            sys.exit(f"{binary}: not in ldconfig's cache (not installed on this machine?)")
        binaries[i] = binary = found.group(1)
        users.setdefault(binary, []).append(binary)
    ldd = subprocess.run(["ldd", binary], capture_output=True, text=True, check=True).stdout
    for path in re.findall(r"=> (/\S+)", ldd):
        users.setdefault(path, []).append(binary)
aliases = {}
for path in users:
    other = path[4:] if path.startswith("/usr/") else "/usr" + path
    aliases[path], aliases[other] = path, path
owners = subprocess.run(["dpkg", "-S", *aliases], capture_output=True, text=True).stdout
owner = {}
for line in owners.splitlines():
    package, _, file = line.partition(": ")
    if file in aliases:
        owner[aliases[file]] = package.split(":")[0]

missing = []
for path, binaries_using in users.items():
    package = owner.get(path)
    # Not from a Debian package (built here), or the sanitizer build's own runtime, which no
    # shipped binary carries.
    if package is None or re.fullmatch(r"lib(a|ub|l|t)san\d*", package):
        continue
    if package not in provided:
        missing += [f"{b}: {path} comes from {package}" for b in binaries_using]
if missing:
    print("deploy/Containerfile's runtime stage does not install:")
    print("\n".join(sorted(set(missing))))
    sys.exit(1)
print(f"every Debian library of {len(binaries)} binaries is installed by the runtime stage")
