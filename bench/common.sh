# What the scripts that time or compare two pathlight builds share (bench/ab-cpu.sh,
# bench/same-images.sh): sourced from the repository root.

# Exits unless every argument is an executable file.
require_executables() {
    for bin in "$@"; do
        [ -x "$bin" ] || { echo "not an executable: $bin" >&2; exit 1; }
    done
}

# Appends to the array SCENES the scene file each argument names: a path to a scene file, or
# a name in scenes/refs; exits on one that is neither.
add_scenes() {
    for name in "$@"; do
        if [ -f "$name" ]; then
            SCENES+=("$name")
        elif [ -f "scenes/refs/$name.toml" ]; then
            SCENES+=("scenes/refs/$name.toml")
        else
            echo "no such scene: $name (neither a file nor scenes/refs/$name.toml)" >&2
            exit 1
        fi
    done
}
