# Sourced by bench/lean/run.sh, bench/scipy/run.sh and settling.sh (not run
# on its own) with `here` set to their folder: makes the virtual
# environment $here/.venv (git-ignored) with the pinned $here/requirements.txt
# if missing or out of date, and sets `py` to its python.
venv=$here/.venv
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
# Reinstall only when the pins change (pip is slow to say "already satisfied").
stamp=$venv/.requirements
if ! cmp -s "$here/requirements.txt" "$stamp"; then
    "$venv/bin/pip" install --quiet --disable-pip-version-check -r "$here/requirements.txt"
    cp "$here/requirements.txt" "$stamp"
fi
py=$venv/bin/python
