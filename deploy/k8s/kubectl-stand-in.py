#!/usr/bin/env python3
"""A stand-in `kubectl` for deploy/k8s/local-test.sh: plays a one-node
cluster with podman, for exactly the subcommands the documented commands use
(docs/running-at-scale.md, "Kubernetes Indexed Job"):

  kubectl apply -f FILE
  kubectl wait --for=condition=complete|failed --timeout=T job/NAME
  kubectl get job/NAME -o jsonpath='{.status.failedIndexes}'
  kubectl get pods -l job-name=NAME
  kubectl logs -l job-name=NAME --prefix

Not a cluster: no API server, no scheduler, no kubelet. What it does:

- PersistentVolumeClaim: a host folder, $KUBECTL_STANDIN_STATE/volumes/NAME
  (an existing folder is kept, as a bound volume keeps its files).
- Job: a background process plays the Job controller, with the semantics
  the Kubernetes documentation gives: pods of the template run with podman
  (`podman run`, one new container per pod, never restarted in place:
  restartPolicy Never), at most `parallelism` at once, until `completions`
  have succeeded; completionMode Indexed sets JOB_COMPLETION_INDEX; a failed
  pod is replaced by a new pod after the pod failure back-off (10 s, doubled
  per failure, at most 6 min; per index with backoffLimitPerIndex); with
  backoffLimitPerIndex an index fails after that many retries, and once more
  than maxFailedIndexes indexes have failed the Job gets FailureTarget, its
  running pods are stopped (terminationGracePeriodSeconds, default 30 s) and
  then it is Failed (the order of Kubernetes 1.31 and later); without it,
  more than backoffLimit failed pods fail the Job.
- Everything about a pod comes from the manifest: image (mapped through
  KUBECTL_STANDIN_IMAGES="from=to,..." to a local image; never pulled),
  command (the entrypoint) and args, env, workingDir, securityContext
  (runAsUser, runAsGroup, fsGroup, supplementalGroups; the container's over
  the pod's), volumes (persistentVolumeClaim, emptyDir) and volumeMounts. As
  the kubelet does for fsGroup, a claim's files are given the group fsGroup,
  g+rw, and its folders g+rwxs, before a pod mounts it. Resource requests
  and limits are ignored (podman would enforce limits only through cgroups,
  and there is no scheduler to place by requests).

State (Job status, pod list, pod logs, every call) is kept under
$KUBECTL_STANDIN_STATE; containers are named $KUBECTL_STANDIN_PREFIX-JOB-
INDEX-ATTEMPT and labelled job-name=JOB.
"""
import json
import os
import re
import signal
import subprocess
import sys
import time

import yaml

STATE = os.environ.get("KUBECTL_STANDIN_STATE", "")
PREFIX = os.environ.get("KUBECTL_STANDIN_PREFIX", "kubectl-stand-in")
PODMAN = os.environ.get("PODMAN", "podman")


def die(message, code=1):
    print(message, file=sys.stderr)
    sys.exit(code)


def now():
    return time.time()


def stamp(t):
    return time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime(t))


def job_dir(name):
    return os.path.join(STATE, "jobs", name)


def read_job(name):
    try:
        with open(os.path.join(job_dir(name), "job.json")) as f:
            return json.load(f)
    except FileNotFoundError:
        return None


def write_job(job):
    path = os.path.join(job_dir(job["metadata"]["name"]), "job.json")
    with open(path + ".tmp", "w") as f:
        json.dump(job, f, indent=1)
    os.replace(path + ".tmp", path)


def not_found(name):
    die(f'Error from server (NotFound): jobs.batch "{name}" not found')


def ranges(indexes):
    """[0, 1, 2, 5] -> "0-2,5", as the Job status writes index sets."""
    out, run = [], []
    for i in sorted(indexes):
        if run and i == run[-1] + 1:
            run.append(i)
            continue
        if run:
            out.append(str(run[0]) if len(run) == 1 else f"{run[0]}-{run[-1]}")
        run = [i]
    if run:
        out.append(str(run[0]) if len(run) == 1 else f"{run[0]}-{run[-1]}")
    return ",".join(out)


def duration(text):
    """Go durations as kubectl takes them: 30s, 5m, 1h, 1h30m, 0.5s."""
    units = {"ms": 0.001, "s": 1, "m": 60, "h": 3600}
    parts = re.findall(r"(\d+(?:\.\d+)?)(ms|s|m|h)", text)
    if not parts or "".join(a + b for a, b in parts) != text:
        die(f'error: invalid argument "{text}" for "--timeout" flag')
    return sum(float(a) * units[b] for a, b in parts)


# ---- apply -----------------------------------------------------------------

def volume_dir(claim):
    return os.path.join(STATE, "volumes", claim)


def apply(path):
    with open(path) as f:
        docs = [d for d in yaml.safe_load_all(f) if d]
    for doc in docs:
        kind = doc.get("kind")
        name = doc["metadata"]["name"]
        if kind == "PersistentVolumeClaim":
            folder = volume_dir(name)
            if os.path.isdir(folder):
                print(f"persistentvolumeclaim/{name} unchanged")
            else:
                os.makedirs(folder, mode=0o755)
                print(f"persistentvolumeclaim/{name} created")
        elif kind == "Job":
            apply_job(doc)
        else:
            die(f"kubectl stand-in: kind {kind} is not played here")


def apply_job(doc):
    name = doc["metadata"]["name"]
    former = read_job(name)
    if former is not None:
        if former["spec"] == doc["spec"]:
            print(f"job.batch/{name} unchanged")
            return
        die(f'The Job "{name}" is invalid: spec.template: Invalid value: '
            "field is immutable")
    pod = doc["spec"]["template"]["spec"]
    if pod.get("restartPolicy") not in ("Never", "OnFailure"):
        die(f'The Job "{name}" is invalid: spec.template.spec.restartPolicy: '
            'Required value: valid values: "OnFailure", "Never"')
    if pod.get("restartPolicy") != "Never":
        die("kubectl stand-in: only restartPolicy Never is played here")
    if doc["spec"].get("backoffLimitPerIndex") is not None and (
            doc["spec"].get("completionMode") != "Indexed"):
        die(f'The Job "{name}" is invalid: spec.backoffLimitPerIndex: '
            "requires completionMode Indexed")
    if len(pod["containers"]) != 1:
        die("kubectl stand-in: only one container a pod is played here")
    for volume in pod.get("volumes", []):
        if "persistentVolumeClaim" in volume:
            claim = volume["persistentVolumeClaim"]["claimName"]
            if not os.path.isdir(volume_dir(claim)):
                # A cluster would leave the pods Pending until the claim exists.
                die(f"kubectl stand-in: no claim {claim}: its pods would stay Pending")
        elif "emptyDir" not in volume:
            die(f"kubectl stand-in: volume {volume['name']}: only "
                "persistentVolumeClaim and emptyDir are played here")
    os.makedirs(os.path.join(job_dir(name), "logs"))
    write_job({
        "kind": "Job",
        "metadata": {"name": name},
        "spec": doc["spec"],
        "status": {"active": 0, "succeeded": 0, "failed": 0,
                   "startTime": stamp(now()), "conditions": []},
        "pods": [],
    })
    with open(os.path.join(job_dir(name), "controller.log"), "w") as log:
        controller = subprocess.Popen(
            [sys.executable, os.path.abspath(__file__), "_controller", name],
            stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
            start_new_session=True)
    with open(os.path.join(job_dir(name), "controller.pid"), "w") as f:
        f.write(f"{controller.pid}\n")
    print(f"job.batch/{name} created")


# ---- the Job controller (in the background) ---------------------------------

def fs_group_ownership(folder, gid):
    """What the kubelet does to a volume for fsGroup (SetVolumeOwnership)."""
    for root, dirs, files in os.walk(folder):
        for path in [root] + [os.path.join(root, f) for f in files]:
            if os.path.islink(path):
                continue
            os.chown(path, -1, gid)
            mode = os.stat(path).st_mode
            if os.path.isdir(path):
                os.chmod(path, mode | 0o2070)
            else:
                os.chmod(path, mode | 0o060)


def podman_run_args(job, index, cname):
    spec = job["spec"]
    pod = spec["template"]["spec"]
    container = pod["containers"][0]
    security = dict(pod.get("securityContext", {}))
    security.update(container.get("securityContext", {}))
    images = dict(pair.split("=", 1) for pair in
                  os.environ.get("KUBECTL_STANDIN_IMAGES", "").split(",") if pair)
    args = [PODMAN, "run", "--rm", "--pull=never", "--name", cname,
            "--label", f"job-name={job['metadata']['name']}",
            "--hostname", cname[len(PREFIX) + 1:]]
    if security.get("runAsUser") is not None:
        user = str(security["runAsUser"])
        if security.get("runAsGroup") is not None:
            user += f":{security['runAsGroup']}"
        args += ["--user", user]
    if security.get("fsGroup") is not None:
        args += ["--group-add", str(security["fsGroup"])]
    for group in security.get("supplementalGroups", []):
        args += ["--group-add", str(group)]
    volumes = {}
    for volume in pod.get("volumes", []):
        if "persistentVolumeClaim" in volume:
            folder = volume_dir(volume["persistentVolumeClaim"]["claimName"])
            if security.get("fsGroup") is not None:
                fs_group_ownership(folder, security["fsGroup"])
        else:
            folder = os.path.join(job_dir(job["metadata"]["name"]), "emptydir",
                                  cname, volume["name"])
            os.makedirs(folder, mode=0o777, exist_ok=True)
            os.chmod(folder, 0o777)
        volumes[volume["name"]] = folder
    for mount in container.get("volumeMounts", []):
        mode = ":ro" if mount.get("readOnly") else ""
        args += ["-v", f"{volumes[mount['name']]}:{mount['mountPath']}{mode}"]
    env = [(e["name"], str(e.get("value", ""))) for e in container.get("env", [])]
    if spec.get("completionMode") == "Indexed":
        env.append(("JOB_COMPLETION_INDEX", str(index)))
    for key, value in env:
        args += ["-e", f"{key}={value}"]
    if container.get("workingDir"):
        args += ["-w", container["workingDir"]]
    if container.get("command"):
        args += ["--entrypoint", json.dumps(container["command"])]
    args.append(images.get(container["image"], container["image"]))
    args += container.get("args", [])
    return args


def controller(name):
    job = read_job(name)
    spec = job["spec"]
    pod_spec = spec["template"]["spec"]
    indexed = spec.get("completionMode") == "Indexed"
    completions = spec.get("completions", 1)
    parallelism = spec.get("parallelism", 1)
    per_index = spec.get("backoffLimitPerIndex")
    max_failed = spec.get("maxFailedIndexes")
    backoff_limit = spec.get("backoffLimit", 6)
    grace = pod_spec.get("terminationGracePeriodSeconds", 30)
    status = job["status"]
    running = {}          # index -> (Popen, pod record)
    succeeded, failed_indexes = set(), set()
    failures = {}         # index -> failed pods (the job's when not per index)
    not_before = {}       # index -> earliest start of its next pod (back-off)
    attempts = {}
    logs = os.path.join(job_dir(name), "logs")

    def stop_all(signum=None, frame=None):
        for proc, pod in running.values():
            subprocess.run([PODMAN, "rm", "-f", "-t", "0", pod["container"]],
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        if signum is not None:
            sys.exit(1)

    signal.signal(signal.SIGTERM, stop_all)

    def save():
        status["active"] = len(running)
        status["succeeded"] = len(succeeded)
        status["failed"] = sum(1 for p in job["pods"] if p["phase"] == "Failed")
        if indexed:
            status["completedIndexes"] = ranges(succeeded)
            if per_index is not None:
                status["failedIndexes"] = ranges(failed_indexes)
        write_job(job)

    def condition(kind, reason, message=""):
        status["conditions"].append({
            "type": kind, "status": "True", "reason": reason,
            "message": message, "lastTransitionTime": stamp(now()),
            "at": now()})  # seconds since the epoch, for the test

    def finish(kind, reason, message=""):
        if kind == "Failed":
            condition("FailureTarget", reason, message)
            save()
            stops = []
            for index, (proc, pod) in running.items():
                stops.append(subprocess.Popen(
                    [PODMAN, "stop", "-t", str(grace), pod["container"]],
                    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
            for stop in stops:
                stop.wait()
            for index, (proc, pod) in running.items():
                pod["exitCode"] = proc.wait()
                pod["phase"] = "Failed"
                pod["stoppedByController"] = True
                pod["ended"] = now()
            running.clear()
        else:
            status["completionTime"] = stamp(now())
        condition(kind, reason, message)
        save()

    save()
    while True:
        # Pods that ended.
        for index, (proc, pod) in list(running.items()):
            code = proc.poll()
            if code is None:
                continue
            del running[index]
            pod["exitCode"] = code
            pod["ended"] = now()
            if code == 0:
                pod["phase"] = "Succeeded"
                succeeded.add(index)
                continue
            pod["phase"] = "Failed"
            key = index if per_index is not None else "job"
            failures[key] = failures.get(key, 0) + 1
            delay = min(10 * 2 ** (failures[key] - 1), 360)
            if per_index is not None:
                not_before[index] = now() + delay
                if failures[key] > per_index:
                    failed_indexes.add(index)
            else:
                not_before = {i: now() + delay for i in range(completions)}
        # Whether the Job is over.
        if per_index is not None:
            if max_failed is not None and len(failed_indexes) > max_failed:
                finish("Failed", "MaxFailedIndexesExceeded",
                       f"Job has exceeded the specified maximal number of failed indexes ({max_failed})")
                return
            if len(succeeded) + len(failed_indexes) == completions and not running:
                if failed_indexes:
                    finish("Failed", "FailedIndexes", "Job has failed indexes")
                else:
                    finish("Complete", "CompletionsReached")
                return
        else:
            if failures.get("job", 0) > backoff_limit:
                finish("Failed", "BackoffLimitExceeded",
                       "Job has reached the specified backoff limit")
                return
            if len(succeeded) == completions:
                finish("Complete", "CompletionsReached")
                return
        # New pods, lowest index first, as many as parallelism allows.
        for index in range(completions):
            if len(running) >= parallelism:
                break
            if index in succeeded or index in failed_indexes or index in running:
                continue
            if not_before.get(index, 0) > now():
                continue
            attempts[index] = attempts.get(index, 0) + 1
            cname = f"{PREFIX}-{name}-{index}-{attempts[index]}"
            log = open(os.path.join(logs, f"{name}-{index}-{attempts[index]}.log"), "w")
            proc = subprocess.Popen(podman_run_args(job, index, cname),
                                    stdin=subprocess.DEVNULL, stdout=log,
                                    stderr=subprocess.STDOUT)
            log.close()
            pod = {"name": f"{name}-{index}-{attempts[index]}", "index": index,
                   "container": cname, "phase": "Running", "started": now()}
            job["pods"].append(pod)
            running[index] = (proc, pod)
        save()
        time.sleep(0.2)


# ---- wait, get, logs --------------------------------------------------------

def wait(argv):
    want, timeout, target = None, 30.0, None
    for arg in argv:
        if arg.startswith("--for=condition="):
            want = arg.split("=", 2)[2].split("=")[0].lower()
        elif arg.startswith("--timeout="):
            timeout = duration(arg.split("=", 1)[1])
        elif arg.startswith("job/"):
            target = arg[4:]
        else:
            die(f"kubectl stand-in: wait {arg} is not played here")
    if want is None or target is None:
        die("kubectl stand-in: wait needs --for=condition=C and job/NAME")
    deadline = now() + timeout
    while True:
        job = read_job(target)
        if job is None:
            not_found(target)
        if any(c["type"].lower() == want and c["status"] == "True"
               for c in job["status"]["conditions"]):
            print(f"job.batch/{target} condition met")
            return
        if now() >= deadline:
            die(f"error: timed out waiting for the condition on jobs/{target}")
        time.sleep(0.5)


def jsonpath(obj, expression):
    match = re.fullmatch(r"\{((?:\.[A-Za-z0-9_]+)+)\}", expression)
    if not match:
        die(f"kubectl stand-in: jsonpath {expression} is not played here")
    for key in match.group(1).split(".")[1:]:
        if not isinstance(obj, dict) or key not in obj:
            return ""
        obj = obj[key]
    return obj if isinstance(obj, str) else json.dumps(obj)


def selected_job(argv):
    for i, arg in enumerate(argv):
        if arg == "-l" and i + 1 < len(argv) and argv[i + 1].startswith("job-name="):
            return argv[i + 1].split("=", 1)[1]
    die("kubectl stand-in: only -l job-name=NAME is played here")


def get(argv):
    if argv[:1] == ["pods"]:
        name = selected_job(argv[1:])
        job = read_job(name)
        pods = job["pods"] if job else []
        if not pods:
            print("No resources found in default namespace.", file=sys.stderr)
            return
        print(f"{'NAME':<32}{'STATUS':<12}{'EXIT':<6}AGE")
        for pod in pods:
            phase = pod["phase"] + ("*" if pod.get("stoppedByController") else "")
            print(f"{pod['name']:<32}{phase:<12}{str(pod.get('exitCode', '')):<6}"
                  f"{int(now() - pod['started'])}s")
        return
    if len(argv) == 3 and argv[0].startswith("job/") and argv[1] == "-o" \
            and argv[2].startswith("jsonpath="):
        name = argv[0][4:]
        job = read_job(name)
        if job is None:
            not_found(name)
        sys.stdout.write(jsonpath(job, argv[2].split("=", 1)[1]))
        return
    die(f"kubectl stand-in: get {' '.join(argv)} is not played here")


def logs(argv):
    name = selected_job(argv)
    prefix = "--prefix" in argv
    job = read_job(name)
    for pod in job["pods"] if job else []:
        container = job["spec"]["template"]["spec"]["containers"][0]["name"]
        with open(os.path.join(job_dir(name), "logs", pod["name"] + ".log")) as f:
            for line in f:
                print((f"[pod/{pod['name']}/{container}] " if prefix else "") + line, end="")


def main(argv):
    if not STATE:
        die("kubectl stand-in: KUBECTL_STANDIN_STATE is not set", 2)
    # Options for a namespace are taken and ignored: there is one.
    while len(argv) >= 2 and argv[0] in ("-n", "--namespace"):
        argv = argv[2:]
    if argv[:1] == ["_controller"]:
        controller(argv[1])
        return
    os.makedirs(os.path.join(STATE, "jobs"), exist_ok=True)
    with open(os.path.join(STATE, "calls.log"), "a") as f:
        f.write(f"{now():.3f} kubectl {' '.join(argv)}\n")
    if len(argv) == 3 and argv[:2] == ["apply", "-f"]:
        apply(argv[2])
    elif argv[:1] == ["wait"]:
        wait(argv[1:])
    elif argv[:1] == ["get"]:
        get(argv[1:])
    elif argv[:1] == ["logs"]:
        logs(argv[1:])
    else:
        die(f"kubectl stand-in: `kubectl {' '.join(argv)}` is not played here")


if __name__ == "__main__":
    main(sys.argv[1:])
