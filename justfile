# unitrace recipes. `just` renders the bundled baseline scene; `just --list` shows the rest.
set shell := ["bash", "-euo", "pipefail", "-c"]

bin := justfile_directory() / "target/release"

# Render the bundled baseline scene to out/baseline.exr and out/baseline.png.
default: (scene "scenes/baseline/Assets/Scenes/Baseline.unity" "baseline")

# Build the release binaries (once; cargo skips the work when nothing changed).
build:
    cargo build --release --workspace --bins --quiet

# Convert, compile (cached) and render one Unity scene to out/NAME.exr and out/NAME.png.
scene SCENE NAME *RENDER_ARGS: build
    mkdir -p "$(dirname "out/{{NAME}}")"
    {{bin}}/unity2soup "{{SCENE}}" -o "out/{{NAME}}.soup"
    kd=$(just --quiet compile "out/{{NAME}}.soup") && \
        {{bin}}/kd2exr "out/{{NAME}}.soup" "$kd" -o "out/{{NAME}}.exr" --preview "out/{{NAME}}.png" {{RENDER_ARGS}}

# Stage 1: Unity scene -> triangle soup.
convert SCENE OUT: build
    {{bin}}/unity2soup "{{SCENE}}" -o "{{OUT}}"

# Stage 2: soup -> k-d tree in cache/ (reused when the geometry is unchanged); prints the tree's path.
compile SOUP: build
    #!/usr/bin/env bash
    set -euo pipefail
    json=$({{bin}}/soup2kd "{{SOUP}}" --cache cache --json)
    path=$(sed -n 's/.*"path":"\([^"]*\)".*/\1/p' <<<"$json")
    cache=$(sed -n 's/.*"cache":"\([^"]*\)".*/\1/p' <<<"$json")
    echo "soup2kd: cache $cache: $path" >&2
    echo "$path"

# Stage 3: soup + tree -> EXR and PNG preview.
render SOUP KD OUT *ARGS: build
    {{bin}}/kd2exr "{{SOUP}}" "{{KD}}" -o "{{OUT}}" --preview "{{without_extension(OUT)}}.png" {{ARGS}}

# Run the whole test suite (the README's test command).
test:
    cargo test --workspace

# Regenerate the bundled Unity projects under scenes/ (meshes, .unity, .meta, .mat).
scenes:
    cargo run --release --quiet -p scenegen -- scenes

# Render every effect scene to out/gallery/NAME.png.
gallery: build
    #!/usr/bin/env bash
    set -euo pipefail
    for dir in scenes/*/; do
        name=$(basename "$dir")
        [ "$name" = gen ] || [ "$name" = baseline ] && continue
        scenes=("$dir"Assets/Scenes/*.unity)
        for scene in "${scenes[@]}"; do
            out=$name
            [ ${#scenes[@]} -gt 1 ] && out=$name-$(basename "$scene" .unity)
            just --quiet scene "$scene" "gallery/$out" --width 480 --height 360 --spp 4
        done
    done
    ls out/gallery/*.png

# Tracer and build benchmarks against brute force and a median-split tree (add `--features embree` via EMBREE=1).
bench: (scene "scenes/baseline/Assets/Scenes/Baseline.unity" "baseline")
    cargo run --release --quiet -p bench {{ if env_var_or_default("EMBREE", "") == "1" { "--features embree" } else { "" } }} --bin kdbench -- --baseline out/baseline.soup --meshes ../shared/corpus/meshes --out reports/bench.md

# What accuracy costs in time: sweep spp, depth, soft-shadow samples and tree settings against a reference.
accuracy:
    cargo run --release --quiet -p bench --bin accuracy

# Scale test: the baseline's props on a SIDE×SIDE grid (16: 10.7 million triangles), converted, compiled and rendered to out/large.exr/.png.
large SIDE="16": build
    {{bin}}/scenegen out --large {{SIDE}}
    just scene out/large/Assets/Scenes/Large.unity large

# FBX scale test: MODELS distinct binary FBX models of 65,536 triangles (16: 1,048,576), each placed twice; times the FBX reader alone on them, then converts, compiles and renders to out/fbxlarge.exr/.png.
fbx-scene MODELS="16": build
    {{bin}}/scenegen out --fbx {{MODELS}}
    {{bin}}/fbxload out/fbxlarge/Assets/Models --runs 3
    just scene out/fbxlarge/Assets/Scenes/FbxLarge.unity fbxlarge

# Render speed-up from 1 to 2 threads on the baseline (interleaved pairs, one process); `just threads --width 320 --height 240`.
threads *ARGS:
    cargo run --release --quiet -p bench --bin threads -- {{ARGS}}

# k-d tree build and traversal table plus what watertightness costs (leaks from inside closed meshes); `just robustbench --only spot`.
robustbench *ARGS:
    cargo run --release --quiet -p bench --bin robustbench -- {{ARGS}}

# Build-parameter experiments with a tree digest per file; `just kdtune 1.5 1 0.5 0 1 out/baseline.soup`.
kdtune *ARGS:
    cargo run --release --quiet -p bench --bin kdtune -- {{ARGS}}

# Render one frame on a Slurm cluster: convert and compile here, render TILES row-band crop tiles as one array job, merge into out/NAME.exr and out/NAME.png (scripts/slurm/render.sh; env CPUS_PER_TASK, PARTITION, TIME_LIMIT, SBATCH_ARGS).
slurm SCENE NAME TILES *KD2EXR_ARGS: build
    mkdir -p "$(dirname "out/{{NAME}}")"
    {{bin}}/unity2soup "{{SCENE}}" -o "out/{{NAME}}.soup"
    kd=$(just --quiet compile "out/{{NAME}}.soup") && \
        KD2EXR="${KD2EXR:-{{bin}}/kd2exr}" scripts/slurm/render.sh "out/{{NAME}}.soup" "$kd" "out/{{NAME}}.exr" {{TILES}} {{KD2EXR_ARGS}}

# Render several scenes on a Slurm cluster, one frame per task of one array job, to out/frames/PROJECT-SCENE.exr/.png; SCENES is one quoted list (globs work): just slurm-frames "scenes/*/Assets/Scenes/*.unity" --spp 4.
slurm-frames SCENES *KD2EXR_ARGS: build
    #!/usr/bin/env bash
    set -euo pipefail
    mkdir -p out/frames
    list=out/frames/frames.tsv
    : > "$list"
    for scene in {{SCENES}}; do
        [ -f "$scene" ] || { echo "slurm-frames: no scene at $scene" >&2; exit 1; }
        project=$(basename "$(dirname "$(dirname "$(dirname "$scene")")")")
        name=$project-$(basename "$scene" .unity)
        {{bin}}/unity2soup "$scene" -o "out/frames/$name.soup"
        kd=$(just --quiet compile "out/frames/$name.soup")
        out=$PWD/out/frames/$name
        printf '%s\t%s\t%s\t%s\n' "$out.soup" "$(realpath "$kd")" "$out.exr" "$out.png" >> "$list"
    done
    KD2EXR="${KD2EXR:-{{bin}}/kd2exr}" scripts/slurm/frames.sh "$list" {{KD2EXR_ARGS}}
