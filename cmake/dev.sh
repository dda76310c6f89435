#!/usr/bin/env bash
# The README's Quick start in one script. Idempotent: installs only what is missing, and
# rebuilds only what changed.
#   bash cmake/dev.sh run    build, then run the skirt scene: a window when there is a display,
#                            otherwise a headless run writing out/skirt.png and out/skirt.json
#   bash cmake/dev.sh test   build, then run the whole test suite (what .ci/run does)
#   bash cmake/dev.sh build  build only
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
what=${1:-run}
case "$what" in
  run|test|build) ;;
  -h|--help) sed -n '2,7p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
  *) echo "dev.sh: unknown command '$what' (use run, test or build)" >&2; exit 2 ;;
esac

bash cmake/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release

bin="$root/build/bin"
case "$what" in
  build) ;;
  test)
    ctest --preset release
    ;;
  run)
    if [[ -n "${DISPLAY:-}" ]] && xdpyinfo >/dev/null 2>&1 || [[ -n "${WAYLAND_DISPLAY:-}" ]]; then
      echo "dev.sh: opening the skirt scene in a window (Esc quits; --help lists the keys)"
      exec "$bin/clothsim_skirt"
    fi
    mkdir -p out
    echo "dev.sh: no display: simulating 20 s of the skirt scene headless"
    "$bin/clothsim_skirt" --headless --seconds 20 --report out/skirt.json
    if [[ -x "$bin/clothsim_skirt" ]] && "$bin/clothsim_skirt" --help 2>/dev/null | grep -q -- '--screenshot'; then
      xvfb-run -a -s "-screen 0 1280x720x24" "$bin/clothsim_skirt" --seconds 20 --screenshot out/skirt.png
    fi
    echo "dev.sh: wrote $(ls out/skirt.* | tr '\n' ' ')"
    ;;
esac
