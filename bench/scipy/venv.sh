# Sourced by run.sh and settling.sh (not run on its own): makes the virtual
# environment bench/scipy/.venv (git-ignored) with the pinned requirements
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
