"""Tables and figures from collected evaluation and recovery results.

Modules: ``tables`` (tab_psnr, tab_null, tab_transfer, tab_margin -> .tex + .csv) and
``figures`` (fig_temporal, fig_teaser, fig_results, fig_damping -> .pdf + .png).
"""
