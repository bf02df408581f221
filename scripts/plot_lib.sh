# Shared by the plot scripts: options every figure takes.  Sourced, not run.

# The gnuplot terminal for --format png|pdf|svg (cairo terminals, 1200x800 at 13 pt).
plot_terminal() {
    case $1 in
        png) echo "pngcairo size 1200,800 font 'Sans,13' noenhanced" ;;
        pdf) echo "pdfcairo size 10in,6.67in font 'Sans,11' linewidth 0.6 noenhanced" ;;
        svg) echo "svg size 1200,800 font 'Sans,13' background rgb 'white' noenhanced" ;;
        *) echo "--format must be png, pdf or svg, got '$1'" >&2; return 2 ;;
    esac
}

# A block index: a whole number >= 0.
plot_check_block() {
    [[ $1 =~ ^[0-9]+$ ]] || { echo "--block needs a block index >= 0, got '$1'" >&2; return 2; }
}

# plot_options "$@": the options every paper figure takes, --format F and --block I, up to
# the first argument that is none.  Sets PLOT_TERMINAL, PLOT_BLOCK and PLOT_SHIFT (how many
# arguments it took).  Returns 2 on a bad or unknown option (said on stderr), 3 for --help.
plot_options() {
    local format=png
    PLOT_BLOCK=0
    PLOT_SHIFT=0
    while [ $# -gt 0 ]; do
        case $1 in
            --format|--block)
                [ $# -ge 2 ] || { echo "$1 needs a value" >&2; return 2; }
                if [ "$1" = --format ]; then format=$2; else PLOT_BLOCK=$2; fi
                shift 2
                PLOT_SHIFT=$((PLOT_SHIFT + 2)) ;;
            -h|--help) return 3 ;;
            -*) echo "unknown option '$1'" >&2; return 2 ;;
            *) break ;;
        esac
    done
    PLOT_TERMINAL=$(plot_terminal "$format") || return 2
    plot_check_block "$PLOT_BLOCK" || return 2
}

# plot_setup SCRIPT HELP_LINES MIN_ARGS "$@": the start every plot script shares.  Parses the
# options (plot_options); --help prints SCRIPT's comment lines HELP_LINES (a sed range) and
# exits 0; a bad option or fewer than MIN_ARGS arguments print the usage line and exit 2.
# Sets PLOT_TERMINAL, PLOT_BLOCK and PLOT_ARGS (the arguments after the options).
plot_setup() {
    local script=$1 help=$2 min=$3 status=0
    shift 3
    plot_options "$@" || status=$?
    [ $status -eq 3 ] && { sed -n "${help}s/^# \{0,1\}//p" "$script"; exit 0; }
    shift "$PLOT_SHIFT"
    if [ $status -ne 0 ] || [ $# -lt "$min" ]; then
        sed -n 's/^# usage: /usage: /p' "$script" >&2
        exit 2
    fi
    PLOT_ARGS=("$@")
}
