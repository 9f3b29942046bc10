#!/usr/bin/env bash
# englobe's render of Bitterli's Cornell box set beside Mitsuba 3's, from the same pbrt-v4 file
# (docs/validation.md, "Against the field's renderers").
#
#   scripts/field-reference.sh [OUT_DIR] [REFERENCE_SPP]
#
# Installs Mitsuba 3 from PyPI into OUT_DIR/venv (once), renders the box with it twice (64 spp,
# the file's count, and REFERENCE_SPP, default 512, with another seed), renders it with englobe
# from the file, and prints `englobe info` of englobe's and Mitsuba's 64-spp images against
# Mitsuba's high-sample one: mean ratios, the back-wall patch's ratios, RMSE and relative MSE.
# If englobe agrees with Mitsuba, both 64-spp images differ from the reference by noise alone:
# their mean ratios are 1 within a fraction of a percent. Their noise differs by design (Mitsuba
# splats each sample into every pixel its filter reaches, pbrt and englobe put it in one), so
# the box is rendered once more by both with a box filter and independent samples, where each
# sample lands in one pixel in both renderers and the relative MSEs compare like with like.
# Takes about 35 minutes on two cores, most of it Mitsuba's reference (its scalar variant).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-target/field-reference}
ref_spp=${2:-512}
scene=../shared/scenes/cornell-bitterli/scene-v4.pbrt
patch=448,200,576,300
mkdir -p "$out"

if [ ! -x "$out/venv/bin/python" ]; then
    python3 -m venv "$out/venv"
    "$out/venv/bin/pip" install --quiet mitsuba
fi
cargo build --release --quiet -p englobe-cli
englobe=target/release/englobe

time_of() { local t0=$SECONDS; "$@"; echo "  ($((SECONDS - t0)) s)"; }
[ -f "$out/mitsuba-$ref_spp.exr" ] ||
    time_of "$out/venv/bin/python" scripts/mitsuba-cornell.py "$scene" "$out/mitsuba-$ref_spp.exr" --spp "$ref_spp" --seed 2
time_of "$out/venv/bin/python" scripts/mitsuba-cornell.py "$scene" "$out/mitsuba-64.exr" --spp 64 --seed 1
time_of "$englobe" render "$scene" -o "$out/englobe-64.exr" --quiet

# The same with a box filter of radius 0.5 and independent samples in both renderers.
sed -e 's/^Sampler "sobol"/Sampler "independent"/' -e 's/^PixelFilter "triangle"/PixelFilter "box"/' \
    -e 's/"float \([xy]\)radius" \[ 1 \]/"float \1radius" [ 0.5 ]/' "$scene" > "$out/box.pbrt"
time_of "$out/venv/bin/python" scripts/mitsuba-cornell.py "$out/box.pbrt" "$out/mitsuba-64-box.exr" --spp 64 --seed 1
time_of "$englobe" render "$out/box.pbrt" -o "$out/englobe-64-box.exr" --quiet

for image in englobe-64 mitsuba-64 englobe-64-box mitsuba-64-box; do
    echo
    "$englobe" info "$out/$image.exr" --patch "$patch" --against "$out/mitsuba-$ref_spp.exr"
done
