//! The offset tilings' arithmetic (GRL's, `docs/reference/grl.md` §5.1),
//! shared by the state's tile coder ([`crate::tile_coding`]) and the
//! actions' tiles ([`crate::action_tiles`]).

/// Start (in sub-tiles) of the tile of tiling `j` that holds `q` along
/// dimension `i`: `c = q − ((q − b) mod T)` with `b = j·(2i + 1)`, wrapped
/// modulo `period` when the dimension wraps.
#[inline]
pub(crate) fn tile_start(q: i32, j: i32, i: i32, t: i32, period: i32) -> i32 {
    let b = j * (2 * i + 1);
    let c = q - (q - b).rem_euclid(t);
    if period > 0 {
        c.rem_euclid(period)
    } else {
        c
    }
}
