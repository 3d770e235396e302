//! The font every plot's text is set in: DejaVu Sans, compiled into the binary and registered
//! once as "sans-serif". Imports nothing of the plots; `mod.rs` and `deformed.rs` import it.

use plotters::style::FontStyle;
use std::sync::OnceLock;

/// DejaVu Sans, compiled in (its licence: `assets/fonts/LICENSE-DejaVu.txt`), so that every
/// plot has its text on any machine.
const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// Registers the embedded font as "sans-serif" once; false only if it would not load.
pub(crate) fn font() -> bool {
    static LOADED: OnceLock<bool> = OnceLock::new();
    *LOADED.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, FONT).is_ok()
    })
}
