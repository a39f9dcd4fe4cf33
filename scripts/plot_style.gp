# plot_style.gp — the settings every figure of scripts/figures.sh and
# scripts/paper.sh loads: UTF-8 text and the palette pound's own charts use
# (cli/plot.c, pd_plot_style): twelve colours told apart on screen and in
# print (Okabe and Ito's without the yellow, six of Paul Tol's muted set),
# solid, then the same dashed, then dash-dotted.
set encoding utf8
array pd_colours[12] = ['#0072B2', '#D55E00', '#009E73', '#CC79A7', '#E69F00', '#56B4E9', \
                        '#332288', '#882255', '#999933', '#44AA99', '#CC6677', '#555555']
array pd_dashes[3] = [1, 2, 4]
do for [k = 1:36] {
    set linetype k lc rgb pd_colours[(k - 1) % 12 + 1] lw 1.5 dt pd_dashes[(k - 1) / 12 + 1] pt (k - 1) % 12 + 1
}
set linetype cycle 36
