#!/usr/bin/env python3
"""Checks deploy/kubernetes/ against what `facet replay --shard` needs (no cluster needed):
an Indexed Job whose completions equal the JOB_COMPLETIONS it passes, each pod writing its own
shard file named by JOB_COMPLETION_INDEX, images mounted read-only, the container's user the
Containerfile's, and a merge Job reading exactly the files the shards write; the PostgreSQL
variant passes a connection string and a station name, with the password from a Secret.
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

central = load("replay-job-postgres.yaml")
central_spec = central["spec"]
central_pod = central_spec["template"]["spec"]
central_container = central_pod["containers"][0]
central_env = {e["name"]: e for e in central_container.get("env", [])}
central_args = central_container.get("args", [])
check(central_spec.get("completionMode") == "Indexed",
      "replay-job-postgres: completionMode must be Indexed")
check(str(central_spec.get("completions")) == central_env.get("JOB_COMPLETIONS", {}).get("value"),
      "replay-job-postgres: completions != JOB_COMPLETIONS")
check(central_container.get("command") == ["facet"] and central_args[:1] == ["replay"],
      "replay-job-postgres: does not run facet replay")
for flag in ("--postgres", "--as-station", "--recipe", "--images"):
    check(flag in central_args, f"replay-job-postgres: {flag} missing")
check("--results" not in central_args and "--shard" not in central_args,
      "replay-job-postgres: no shard file and no --shard (the Job's environment gives it)")
check("secretKeyRef" in central_env.get("PGPASSWORD", {}).get("valueFrom", {}),
      "replay-job-postgres: PGPASSWORD must come from a Secret")
check(all("password" not in str(e.get("value", "")) for e in central_env.values()),
      "replay-job-postgres: no password in plain env values")
for var in re.findall(r"\$\((\w+)\)", " ".join(central_args)):
    check(var in central_env, f"replay-job-postgres: $({var}) is not set")
check({m["name"]: m for m in central_container["volumeMounts"]}["images"].get("readOnly") is True,
      "replay-job-postgres: images must be read-only")

with open(f"{root}/deploy/Containerfile") as f:
    containerfile = f.read()
uid = re.search(r"useradd [^\n]*--uid (\d+)", containerfile)
check(uid is not None, "Containerfile: user facet needs a fixed --uid")
for name, manifest in (("replay-job", job), ("merge-job", merge), ("replay-job-postgres", central)):
    user = manifest["spec"]["template"]["spec"]["securityContext"]["runAsUser"]
    check(uid is not None and str(user) == uid.group(1),
          f"{name}: runAsUser {user} is not the Containerfile's uid")
check("libmosquitto1" in containerfile and "libpq5" in containerfile,
      "Containerfile: the runtime needs libmosquitto1 and libpq5")

for e in errors:
    print(e)
sys.exit(1 if errors else 0)
