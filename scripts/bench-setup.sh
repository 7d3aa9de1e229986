# Sourced by the measuring scripts in this folder (not run on its own): sets
# `python` (bench/lean's virtual environment, with pyarrow, made if missing),
# `study` (the dev build, built here) and `out` (a fresh results folder named
# after $1), and reports the folder and the load average on stderr.
python=$root/bench/lean/.venv/bin/python
if [ ! -x "$python" ]; then
    python3 -m venv "$root/bench/lean/.venv"
    "$python" -m pip install --quiet --disable-pip-version-check -r "$root/bench/lean/requirements.txt"
fi
(cd "$root" && cargo build --quiet --bin study)
study=${CARGO_TARGET_DIR:-$root/target}/debug/study
out=$(mktemp -d "${TMPDIR:-/tmp}/autobal-$1.XXXXXX")
echo "results: $out   (load average: $(cut -d' ' -f1-3 /proc/loadavg))" >&2
