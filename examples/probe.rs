use crush::solver::*;
use std::io::Write;
use std::sync::atomic::AtomicBool;
struct P(usize);
impl Observer for P {
    fn on_history(&mut self, r: &HistoryRow) {
        self.0 += 1;
        if self.0 % 20 == 0 {
            eprintln!(
                "u {:7.3} P {:9.1} Pb {:9.1} KE {:9.3} IE {:9.3} PL {:9.3} W {:9.3} F {:8.3}",
                r.displacement_mm,
                r.load_top_n,
                r.load_bottom_n,
                r.kinetic_mj,
                r.internal_mj,
                r.plastic_mj,
                r.external_mj,
                r.friction_mj
            );
        }
    }
}
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let case = Case::from_json(&text, &Limits::default()).unwrap();
    let out = run(&case, &mut P(0), &AtomicBool::new(false));
    match out {
        Ok(o) => {
            println!("{:#?}", o.summary);
            let stem = std::path::Path::new(&path)
                .file_stem()
                .unwrap()
                .to_string_lossy()
                .to_string();
            let mut f = std::fs::File::create(format!("/tmp/{stem}.snap.csv")).unwrap();
            for i in 0..o.snapshot.position_mm.len() {
                let (a, b) = (o.snapshot.initial_mm[i], o.snapshot.position_mm[i]);
                writeln!(
                    f,
                    "{},{},{},{},{},{},{}",
                    a[0], a[1], a[2], b[0], b[1], b[2], o.snapshot.plastic_strain[i]
                )
                .unwrap();
            }
            let mut f = std::fs::File::create(format!("/tmp/{stem}.hist.csv")).unwrap();
            for r in &o.history {
                writeln!(f, "{}", r.values().map(|v| v.to_string()).join(",")).unwrap();
            }
        }
        Err(e) => println!("ERROR {e}"),
    }
}
