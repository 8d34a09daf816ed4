#!/usr/bin/env bash
# Soak: a managed scene (the rooftops' surfaces under their [budget]) with a player and a sledge
# that never stop moving, run for FRAMES frames (default 100,000) with resident memory logged every
# 10,000 frames. Usage: scripts/soak.sh [FRAMES]; BIN names the binary (default
# target/release/snowprint), WORK the scratch folder, REPORT=1 adds --report WORK/report.json.
# docs/RELIABILITY.md records a run.
set -euo pipefail
FRAMES=${1:-100000}
BIN=${BIN:-target/release/snowprint}
WORK=${WORK:-$(mktemp -d)}
mkdir -p "$WORK"
SCENE="$WORK/soak.toml"
# The scene's motion covers the whole run at 60 frames a second: keys every 0.5 s, the player
# walking to and fro across roof_a and roof_b (10 s a round), the sledge along the street (14 s).
SECONDS_OF_MOTION=$(( FRAMES / 60 + 2 ))
{
  sed -n '/^version/,/^# The player/p' scenes/rooftops.toml | sed '$d'
  echo '[[deformer]]'
  echo 'name = "player"'
  echo 'shape = "sphere"'
  echo 'radius = 0.12'
  echo 'player = true'
  echo 'keys = ['
  awk -v n=$(( SECONDS_OF_MOTION * 2 )) 'BEGIN { for (k = 0; k <= n; k++) { t = k / 2; p = (t % 10) / 5; x = (p < 1) ? -5.5 + 7.5 * p : 2.0 - 7.5 * (p - 1); printf "    { t = %.1f, position = [%.3f, 6.1, 0.0] },\n", t, x } }'
  echo ']'
  echo '[[deformer]]'
  echo 'name = "sledge"'
  echo 'shape = "box"'
  echo 'half_extents = [0.3, 0.1, 0.2]'
  echo 'keys = ['
  awk -v n=$(( SECONDS_OF_MOTION * 2 )) 'BEGIN { for (k = 0; k <= n; k++) { t = k / 2; p = (t % 14) / 7; x = (p < 1) ? -6.0 + 12.0 * p : 6.0 - 12.0 * (p - 1); printf "    { t = %.1f, position = [%.3f, 0.05, 4.0] },\n", t, x } }'
  echo ']'
} > "$SCENE"
echo "soak: $FRAMES frames of $SCENE ($(wc -c < "$SCENE") bytes), dump in $WORK/dump" >&2
start=$(date +%s)
SNOWPRINT_LOG=info "$BIN" simulate --scene "$SCENE" --frames "$FRAMES" --dump "$WORK/dump" \
  ${REPORT:+--report "$WORK/report.json"} 2>&1 \
  | grep --line-buffered -E 'resident memory|^snowprint: (error|.*failed)' \
  | sed -u -E 's/.*(frame [0-9]+: resident memory [0-9]+ KiB).*/\1/'
echo "soak: done in $(( $(date +%s) - start )) s" >&2
