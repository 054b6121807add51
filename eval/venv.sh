# Sourced by eval/run, eval/scale, eval/scaling and eval/reconstruction: sets up eval/.venv from the pinned eval/requirements.txt
# (first run only, or when the file changes), builds remesh in release mode, and exports
# REMESH_BIN and PYTHON.
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(dirname "$here")"
venv="$here/.venv"
stamp="$venv/.requirements.sha"
want="$(sha256sum "$here/requirements.txt" | cut -d' ' -f1)"
if [[ ! -x "$venv/bin/python" || ! -f "$stamp" || "$(cat "$stamp")" != "$want" ]]; then
  echo "eval: creating $venv from eval/requirements.txt" >&2
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet --disable-pip-version-check -r "$here/requirements.txt"
  echo "$want" > "$stamp"
fi
echo "eval: building remesh (release)" >&2
(cd "$root" && cargo build --release --quiet --bin remesh)
# A REMESH_BIN given (another build, to compare) is kept.
export REMESH_BIN="${REMESH_BIN:-${CARGO_TARGET_DIR:-$root/target}/release/remesh}"
PYTHON="$venv/bin/python"
