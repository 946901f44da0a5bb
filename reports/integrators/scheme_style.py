"""Colour and line style per scheme, shared by the integrator figures so they match."""
STYLE = {
    "usf": ("tab:blue", "-"),
    "usl": ("tab:orange", "-"),
    "musl": ("tab:green", ":"),
    "pc_published": ("tab:red", "-"),
    "pc_newmark": ("black", "--"),
    "gen_alpha_grid_rb0.0": ("tab:purple", "-"),
    "gen_alpha_grid_rb0.5": ("tab:brown", "-"),
    "gen_alpha_grid_rb0.8": ("tab:pink", "-"),
    "gen_alpha_grid_rb1.0": ("tab:olive", "-"),
}
