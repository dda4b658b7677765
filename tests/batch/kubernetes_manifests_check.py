#!/usr/bin/env python3
"""Checks deploy/kubernetes/ against what `facet replay --shard` needs (no cluster needed):
an Indexed Job whose completions equal the JOB_COMPLETIONS it passes, each pod writing its own
shard file named by JOB_COMPLETION_INDEX, images mounted read-only, the container's user the
Containerfile's, and a merge Job reading exactly the files the shards write.
Usage: kubernetes_manifests_check.py REPO_ROOT"""
import re
import sys

import yaml

root = sys.argv[1]
errors = []


def check(condition, message):
    if not condition:
        errors.append(message)


def load(name):
    with open(f"{root}/deploy/kubernetes/{name}") as f:
        return yaml.safe_load(f)


job = load("replay-job.yaml")
spec = job["spec"]
pod = spec["template"]["spec"]
container = pod["containers"][0]
env = {e["name"]: e.get("value") for e in container.get("env", [])}
script = " ".join(container.get("args", []))
check(job["kind"] == "Job" and job["apiVersion"] == "batch/v1", "replay-job: not a batch/v1 Job")
check(spec.get("completionMode") == "Indexed", "replay-job: completionMode must be Indexed")
check(str(spec.get("completions")) == env.get("JOB_COMPLETIONS"),
      f"replay-job: completions {spec.get('completions')} != JOB_COMPLETIONS {env.get('JOB_COMPLETIONS')}")
check(pod.get("restartPolicy") == "Never", "replay-job: restartPolicy must be Never")
check("facet replay" in script, "replay-job: does not run facet replay")
check("--results /results/shard-$(JOB_COMPLETION_INDEX).db" in script,
      "replay-job: each pod must write its own shard file")
check("--shard" not in script, "replay-job: the shard comes from the Job's environment")
mounts = {m["name"]: m for m in container["volumeMounts"]}
check(mounts.get("images", {}).get("readOnly") is True, "replay-job: images must be read-only")
for var in re.findall(r"\$\((\w+)\)", script):
    check(var in env or var == "JOB_COMPLETION_INDEX", f"replay-job: $({var}) is not set")

merge = load("merge-job.yaml")
merge_script = " ".join(merge["spec"]["template"]["spec"]["containers"][0]["args"])
check("facet results merge /results/shard-*.db --out /results/all.db" in merge_script,
      "merge-job: must merge every shard file into /results/all.db")

with open(f"{root}/deploy/Containerfile") as f:
    containerfile = f.read()
uid = re.search(r"useradd [^\n]*--uid (\d+)", containerfile)
check(uid is not None, "Containerfile: user facet needs a fixed --uid")
for name, manifest in (("replay-job", job), ("merge-job", merge)):
    user = manifest["spec"]["template"]["spec"]["securityContext"]["runAsUser"]
    check(uid is not None and str(user) == uid.group(1),
          f"{name}: runAsUser {user} is not the Containerfile's uid")
check("libmosquitto1" in containerfile and "libpq5" in containerfile,
      "Containerfile: the runtime needs libmosquitto1 and libpq5")

for e in errors:
    print(e)
sys.exit(1 if errors else 0)
