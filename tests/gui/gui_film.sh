#!/usr/bin/env bash
# The viewer and film files under Xvfb: it continues a film saved by `pdflab
# render` (its image equals the command line's continuation of the same film),
# Ctrl+S saves its accumulation as a film that the command line continues, and
# an EXR or a film loads as the reference.
#   gui_film.sh PDFLAB SCENE ARTIFACT_DIR
set -euo pipefail

source "$(dirname "$0")/lib.sh"
inside_xvfb "1280x800x24" "xdotool" "$0" "$@"
shift
pdflab=$1 scene=$2 art=$3
rm -rf "$art"
mkdir -p "$art/shots"

echo "== the viewer continues a film from the command line"
"$pdflab" render --scene "$scene" --strategy cosine --spp 8 --seed 3 --film-out "$art/part.film" --quiet
"$pdflab" --resume "$art/part.film" --spp 24 --screenshot "$art/continued.png"
[ "$(json_field "$art/continued.json" spp)" = 24 ] || fail "continued.json spp"
"$pdflab" render --resume "$art/part.film" --spp 24 --film-out "$art/cli.film" --out "$art/cli.pfm" --quiet
cmp "$art/continued.pfm" "$art/cli.pfm" || fail "the viewer's continuation differs from render --resume"
echo "viewer continuation of 8 -> 24 spp equals render --resume, bit for bit"

echo "== a film of other settings is refused before a window opens"
set +e
"$pdflab" --resume "$art/part.film" --strategy light --spp 24 --screenshot "$art/never.png" 2>"$art/bad_resume.txt"
status=$?
set -e
[ "$status" -eq 2 ] || fail "--resume with another strategy: expected status 2, got $status"
grep -q "strategy" "$art/bad_resume.txt" || fail "the message does not name the strategy: $(cat "$art/bad_resume.txt")"
[ ! -e "$art/never.png" ] || fail "bad input left a screenshot"

echo "== Ctrl+S saves the accumulation as a film"
PDFLAB_SCREENSHOT_DIR="$art/shots" start_viewer "$pdflab" --scene "$scene" --strategy cosine --spp 16
sleep 2
alive "$viewer" "start-up"
send_key ctrl+s
for _ in $(seq 50); do ls "$art"/shots/*.film >/dev/null 2>&1 && break; sleep 0.1; done
saved=$(ls "$art"/shots/*.film | head -1)
[ -s "$saved" ] || fail "Ctrl+S wrote no film"
send_key F12
sleep 1
quit_viewer
"$pdflab" merge "$saved" --stats-json "$art/saved.json" --out "$art/saved.exr" >/dev/null
[ "$(json_field "$art/saved.json" spp)" = 16 ] || fail "the saved film holds $(json_field "$art/saved.json" spp) spp, not 16"
"$pdflab" render --resume "$saved" --spp 32 --film-out "$art/more.film" --out "$art/more.pfm" --quiet
"$pdflab" render --scene "$scene" --strategy cosine --spp 32 --out "$art/direct.pfm" --quiet
cmp "$art/more.pfm" "$art/direct.pfm" || fail "the saved film continued does not equal a direct render"
echo "Ctrl+S film ($saved) continued to 32 spp equals a direct 32 spp render"

echo "== an EXR and a film load as the reference"
"$pdflab" render --scene "$scene" --strategy cosine --spp 64 --seed 7 --out "$art/ref.exr" --film-out "$art/ref.film" --quiet
"$pdflab" --scene "$scene" --strategy cosine --spp 4 --reference "$art/ref.exr" --screenshot "$art/with_exr.png"
"$pdflab" --scene "$scene" --strategy cosine --spp 4 --reference "$art/ref.film" --screenshot "$art/with_film.png"
[ -s "$art/with_exr.png" ] && [ -s "$art/with_film.png" ] || fail "no screenshot with an EXR or film reference"
cp "$art/continued.png" "$art/screen.png"
echo "PASS"
