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
