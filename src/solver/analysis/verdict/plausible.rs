//! Whether a tube's dimensions are those of any tube measured (wall thickness t, slenderness
//! d/t, length over width l/d), and, when they are not, the unit slip — metres, inches or
//! micrometres typed into a millimetre field — that would bring them back. Lengths in mm.

use crate::solver::model::geometry::{CrossSection, Outline};

/// The thinnest wall, mm: half the 0.1 mm wall of a drinks can, the thinnest tube crushed in
/// the literature; the examples' thinnest is 0.76 mm. A thickness in metres typed as mm (3.2 mm as
/// 0.0032) lands a factor 15 or more below it.
pub const T_MIN_MM: f64 = 0.05;
/// The thickest, mm: crash-absorber tubes and the steel pipes crushed laterally stay within
/// 20 mm; 50 leaves room. A thickness in micrometres (3200 for 3.2 mm) lands far above it.
pub const T_MAX_MM: f64 = 50.0;
/// The squattest wall, d/t: the case's own check makes d more than 2t, and Andrews et al.
/// (1983) crushed tubes down to t/d 0.35 (d/t 2.9); the examples' squattest is 6.9.
pub const DT_MIN: f64 = 2.5;
/// The most slender, d/t: Guillow et al. (2001) crushed aluminium tubes up to d/t 450, past
/// the 10–100 of crash structures; the examples reach 27 (the square tube's b/t). A thickness
/// in metres on a diameter in mm gives thousands.
pub const DT_MAX: f64 = 500.0;
/// The shortest tube over its width, l/d: a ring sliced for a lateral ring test is a tenth of
/// its diameter long; the examples are 2–7.6. A length in metres gives a thousandth.
pub const LD_MIN: f64 = 0.1;
/// The longest: a column 50 diameters long buckles as a whole long before it folds, and no
/// crush test uses one; a length in micrometres gives thousands.
pub const LD_MAX: f64 = 50.0;

/// A geometry outside every tube measured: what is out, and the slip that would explain it.
#[derive(Debug, Clone, PartialEq)]
pub struct Implausible {
    /// The figures out of range, each with its range: "t = 0.0032 mm (0.05–50 mm)".
    pub out: Vec<String>,
    /// The likely unit slip, when one brings every figure into range.
    pub slip: Option<Slip>,
}

/// A unit slip: which lengths, by what factor, said as a question.
#[derive(Debug, Clone, PartialEq)]
pub struct Slip {
    /// The factor the lengths were meant to be multiplied by: 1000, 25.4 or 0.001.
    pub factor: f64,
    /// "thickness 0.0032 mm = 3.2 µm: did you mean 3.2 mm (metres typed as millimetres)?"
    pub question: String,
}

/// The unit slips looked for, likeliest first: the factor the typed value is short by, and
/// what was typed.
const SLIPS: [(f64, &str); 3] = [
    (1000.0, "metres typed as millimetres"),
    (0.001, "micrometres typed as millimetres"),
    (25.4, "inches typed as millimetres"),
];

/// The tube's lengths, mm.
#[derive(Debug, Clone, Copy)]
struct Lengths {
    t: f64,
    w: f64,
    l: f64,
}

impl Lengths {
    /// Each figure out of its range, with the range.
    fn out(self, w_symbol: &str) -> Vec<String> {
        let mut out = Vec::new();
        let mut check = |name: String, v: f64, lo: f64, hi: f64, unit: &str| {
            if !(lo..=hi).contains(&v) {
                out.push(format!(
                    "{name} = {}{unit} ({}–{}{unit})",
                    sig(v),
                    sig(lo),
                    sig(hi)
                ));
            }
        };
        check("t".into(), self.t, T_MIN_MM, T_MAX_MM, " mm");
        check(format!("{w_symbol}/t"), self.w / self.t, DT_MIN, DT_MAX, "");
        check(format!("l/{w_symbol}"), self.l / self.w, LD_MIN, LD_MAX, "");
        out
    }
}

/// The finding for a tube of this section and length, none when every figure is in range.
pub fn check(section: &CrossSection, length_mm: f64) -> Option<Implausible> {
    let given = Lengths {
        t: section.thickness_mm(),
        w: section.width_mm(),
        l: length_mm,
    };
    let symbol = section.width_symbol();
    let out = given.out(symbol);
    if out.is_empty() {
        return None;
    }
    let width = section.width_name();
    let slip = SLIPS.iter().find_map(|&(factor, typed)| {
        let scaled = |which: usize| {
            let mut s = given;
            match which {
                0 => s.t *= factor,
                1 => s.w *= factor,
                2 => s.l *= factor,
                _ => (s.t, s.w, s.l) = (s.t * factor, s.w * factor, s.l * factor),
            }
            s
        };
        let which = (0..4).find(|&i| scaled(i).out(symbol).is_empty())?;
        let one = |name: &str, v: f64| {
            format!(
                "{name} {} mm{}: did you mean {} mm ({typed})?",
                sig(v),
                plain(v),
                sig(v * factor)
            )
        };
        let question = match which {
            0 => one("thickness", given.t),
            1 => one(width, given.w),
            2 => one("length", given.l),
            _ => format!(
                "thickness, {width} and length {}, {} and {} mm: did you mean {}, {} and {} mm \
                 ({typed})?",
                sig(given.t),
                sig(given.w),
                sig(given.l),
                sig(given.t * factor),
                sig(given.w * factor),
                sig(given.l * factor)
            ),
        };
        Some(Slip { factor, question })
    });
    Some(Implausible { out, slip })
}

/// A length in mm said in the unit it reads best in, when that is not mm: " = 3.2 µm".
fn plain(mm: f64) -> String {
    if mm < 0.1 {
        format!(" = {} µm", sig(mm * 1000.0))
    } else if mm >= 1000.0 {
        format!(" = {} m", sig(mm / 1000.0))
    } else {
        String::new()
    }
}

/// A figure to four significant digits, without trailing zeros: 0.0032, 3.2, 6938, 1.2e6.
pub fn sig(x: f64) -> String {
    if !x.is_finite() || x == 0.0 {
        return format!("{x}");
    }
    let magnitude = x.abs().log10().floor();
    if !(-4.0..6.0).contains(&magnitude) {
        return format!("{x:.3e}");
    }
    let decimals = (3.0 - magnitude).max(0.0) as usize;
    let s = format!("{x:.decimals$}");
    match s.contains('.') {
        true => s.trim_end_matches('0').trim_end_matches('.').into(),
        false => s,
    }
}
