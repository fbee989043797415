//! Experience: successive missions of one robot, its case base carried
//! from each to the next and learning on line (Urdiales et al. 2006: the
//! reactive layer "improves with experience"), and evaluations of the case
//! base as it stands after so many missions: held-out missions, learning
//! off (no teacher), counted done or not. What each mission gave, the
//! tables a person reads, and the curve (`experience.svg`, plotters).
//!
//! The missions are run by [`crate::missions`] (`situ run --missions N`, or a test);
//! this module only holds and shows their results.

use plotters::prelude::*;
use situ_sim::plot::{err, PlotError};
use std::fmt::Write;

/// What one mission gave.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Mission {
    /// From 1.
    pub index: usize,
    /// Its noise seed (the laser's noise, the walking person).
    pub seed: u64,
    /// The goal reached with no collision.
    pub done: bool,
    /// It ended in a collision.
    pub collision: bool,
    /// When it ended (s): at the goal, or how else it ended.
    pub end: f64,
    /// The outcome, for a person.
    pub outcome: String,
    /// Distance driven (m).
    pub distance: f64,
    /// Routes computed.
    pub routes: u64,
    /// Situations the teacher had to drive (novel, or where the nearest case
    /// drove towards something too close): the cases learnt on line.
    pub learnt: u64,
    /// Cases in the base after the mission.
    pub cases: usize,
}

/// The figures of a run of missions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Share {
    /// Missions counted.
    pub missions: usize,
    /// Of which done.
    pub done: usize,
    /// Mean cases learnt on line per mission.
    pub mean_learnt: f64,
    /// Mean time to the goal of the missions done (s), if any.
    pub mean_time: Option<f64>,
}

impl Share {
    fn of(missions: &[Mission]) -> Share {
        let done: Vec<&Mission> = missions.iter().filter(|m| m.done).collect();
        let n = missions.len().max(1) as f64;
        Share {
            missions: missions.len(),
            done: done.len(),
            mean_learnt: missions.iter().map(|m| m.learnt as f64).sum::<f64>() / n,
            mean_time: (!done.is_empty()).then(|| done.iter().map(|m| m.end).sum::<f64>() / done.len() as f64),
        }
    }

    /// The share of missions done, in [0, 1].
    pub fn success_rate(&self) -> f64 {
        self.done as f64 / self.missions.max(1) as f64
    }
}

/// The case base as it stood after `after` learning missions, tried on
/// held-out missions with learning off.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Evaluation {
    /// Learning missions before it.
    pub after: usize,
    /// Cases in the base then.
    pub cases: usize,
    /// The held-out missions, in order.
    pub missions: Vec<Mission>,
}

impl Evaluation {
    /// Its figures.
    pub fn share(&self) -> Share {
        Share::of(&self.missions)
    }
    /// Missions that ended in a collision.
    pub fn collisions(&self) -> usize {
        self.missions.iter().filter(|m| m.collision).count()
    }
}

/// Successive missions, in order, and the evaluations between them.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct Experience {
    /// The learning missions.
    pub missions: Vec<Mission>,
    /// The evaluations, by `after`.
    pub evaluations: Vec<Evaluation>,
}

/// After how many learning missions of `n` to evaluate: 0, then about six
/// steps, then `n`.
pub fn evaluation_points(n: usize) -> Vec<usize> {
    let step = n.div_ceil(6).max(1);
    let mut points: Vec<usize> = (0..n).step_by(step).collect();
    points.push(n);
    points
}

impl Experience {
    /// The first half of the missions and the second (the middle mission of
    /// an odd count goes to the second).
    pub fn halves(&self) -> (Share, Share) {
        let mid = self.missions.len() / 2;
        (Share::of(&self.missions[..mid]), Share::of(&self.missions[mid..]))
    }

    /// Simulated time over every mission, evaluations included (s).
    pub fn simulated(&self) -> f64 {
        let held_out: f64 = self.evaluations.iter().flat_map(|e| &e.missions).map(|m| m.end).sum();
        self.missions.iter().map(|m| m.end).sum::<f64>() + held_out
    }

    /// The evaluations' table: one line per evaluation.
    pub fn evaluation_table(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "  {:>5}  {:>6}  {:>10}  {:>10}  {:>13}",
            "after", "cases", "done", "collisions", "mean time (s)"
        );
        for e in &self.evaluations {
            let h = e.share();
            let time = h.mean_time.map_or("-".to_string(), |t| format!("{t:.1}"));
            let done = format!("{}/{} {:>3.0} %", h.done, h.missions, 100.0 * h.success_rate());
            let _ = writeln!(s, "  {:>5}  {:>6}  {:>10}  {:>10}  {:>13}", e.after, e.cases, done, e.collisions(), time);
        }
        s
    }

    /// The table: one line per mission, then the two halves.
    pub fn table(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "  {:>7}  {:>4}  {:<38}  {:>8}  {:>6}  {:>6}  {:>6}",
            "mission", "seed", "outcome", "dist (m)", "routes", "learnt", "cases"
        );
        for m in &self.missions {
            let _ = writeln!(
                s,
                "  {:>7}  {:>4}  {:<38}  {:>8.1}  {:>6}  {:>6}  {:>6}",
                m.index, m.seed, m.outcome, m.distance, m.routes, m.learnt, m.cases
            );
        }
        if self.missions.len() >= 2 {
            let (a, b) = self.halves();
            let line = |name: &str, h: &Share| {
                let time = h.mean_time.map_or("-".to_string(), |t| format!("{t:.1} s"));
                format!(
                    "  {name:<12} {}/{} done ({:.0} %), {:.1} cases learnt per mission, mean time to goal {time}\n",
                    h.done,
                    h.missions,
                    100.0 * h.success_rate(),
                    h.mean_learnt
                )
            };
            s.push('\n');
            s.push_str(&line("first half", &a));
            s.push_str(&line("second half", &b));
        }
        s
    }

    /// `experience.svg`: above, the share of held-out missions done with
    /// learning off, after so many learning missions (the curve); below,
    /// the cases the teacher had to give in each learning mission.
    pub fn svg(&self, title: &str) -> Result<String, PlotError> {
        let n = self.missions.len().max(1) as f64;
        let l_max = self.missions.iter().map(|m| m.learnt).max().unwrap_or(1).max(1) as f64 * 1.15;
        let green = RGBColor(44, 160, 44);
        let red = RGBColor(214, 39, 40);
        let blue = RGBColor(31, 119, 180);
        let mut buf = String::new();
        {
            let root = SVGBackend::with_string(&mut buf, (1000, 640)).into_drawing_area();
            root.fill(&WHITE).map_err(err)?;
            let root = root.titled(title, ("sans-serif", 20)).map_err(err)?;
            let (top, bottom) = root.split_vertically(330);
            let mut chart = ChartBuilder::on(&top)
                .margin(10)
                .x_label_area_size(25)
                .y_label_area_size(60)
                .build_cartesian_2d(-0.5..n + 0.5, 0.0..105.0)
                .map_err(err)?;
            chart
                .configure_mesh()
                .y_desc("held-out missions done (%)")
                .x_labels(20)
                .x_label_formatter(&|x| format!("{x:.0}"))
                .draw()
                .map_err(err)?;
            let done: Vec<(f64, f64)> =
                self.evaluations.iter().map(|e| (e.after as f64, 100.0 * e.share().success_rate())).collect();
            chart
                .draw_series(LineSeries::new(done.clone(), green.stroke_width(2)))
                .map_err(err)?
                .label("done, learning off")
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], green.stroke_width(2)));
            chart.draw_series(done.iter().map(|&p| Circle::new(p, 4, green.filled()))).map_err(err)?;
            let hit: Vec<(f64, f64)> = self
                .evaluations
                .iter()
                .map(|e| (e.after as f64, 100.0 * e.collisions() as f64 / e.missions.len().max(1) as f64))
                .collect();
            chart
                .draw_series(LineSeries::new(hit, red.stroke_width(2)))
                .map_err(err)?
                .label("ended in a collision")
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], red.stroke_width(2)));
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::MiddleRight)
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .draw()
                .map_err(err)?;
            let mut chart = ChartBuilder::on(&bottom)
                .margin(10)
                .x_label_area_size(35)
                .y_label_area_size(60)
                .build_cartesian_2d(-0.5..n + 0.5, 0.0..l_max)
                .map_err(err)?;
            chart
                .configure_mesh()
                .x_desc("learning missions")
                .y_desc("cases learnt on line")
                .x_labels(20)
                .x_label_formatter(&|x| format!("{x:.0}"))
                .draw()
                .map_err(err)?;
            chart
                .draw_series(self.missions.iter().map(|m| {
                    let x = m.index as f64 - 0.5;
                    Rectangle::new([(x - 0.3, 0.0), (x + 0.3, m.learnt as f64)], blue.mix(0.7).filled())
                }))
                .map_err(err)?;
            root.present().map_err(err)?;
        }
        Ok(buf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mission(index: usize, done: bool, end: f64, learnt: u64) -> Mission {
        let outcome = if done { "goal" } else { "timeout" }.to_string();
        Mission {
            index,
            seed: index as u64,
            done,
            collision: false,
            end,
            outcome,
            distance: 1.0,
            routes: 1,
            learnt,
            cases: 10 * index,
        }
    }

    #[test]
    fn the_halves_split_the_missions_and_count_them() {
        let e = Experience {
            missions: vec![
                mission(1, false, 300.0, 100),
                mission(2, true, 80.0, 50),
                mission(3, true, 70.0, 20),
                mission(4, true, 60.0, 10),
                mission(5, true, 50.0, 0),
            ],
            evaluations: vec![
                Evaluation { after: 0, cases: 5, missions: vec![mission(1, false, 9.0, 0), mission(2, true, 1.0, 0)] },
                Evaluation { after: 5, cases: 50, missions: vec![mission(1, true, 3.0, 0), mission(2, true, 1.0, 0)] },
            ],
        };
        let (a, b) = e.halves();
        assert_eq!((a.missions, a.done), (2, 1));
        assert_eq!((b.missions, b.done), (3, 3));
        assert_eq!(a.mean_learnt, 75.0);
        assert_eq!(a.mean_time, Some(80.0));
        assert_eq!(b.mean_time, Some(60.0));
        assert_eq!(b.success_rate(), 1.0);
        assert_eq!(e.simulated(), 574.0);
        let evals = e.evaluation_table();
        assert!(evals.contains("      0       5   1/2  50 %"), "{evals}");
        assert!(evals.contains("      5      50   2/2 100 %"), "{evals}");
        let table = e.table();
        assert!(table.contains("first half   1/2 done (50 %), 75.0 cases learnt per mission, mean time to goal 80.0 s"));
        assert!(table.contains("second half  3/3 done (100 %)"));
        let svg = e.svg("experience").expect("drawn");
        assert!(svg.starts_with("<svg") && svg.contains("cases learnt on line"));
    }

    #[test]
    fn no_mission_done_has_no_mean_time() {
        let e = Experience {
            missions: vec![mission(1, false, 300.0, 5), mission(2, false, 300.0, 5)],
            evaluations: vec![],
        };
        assert_eq!(e.halves().0.mean_time, None);
        assert!(e.table().contains("mean time to goal -"));
    }

    #[test]
    fn evaluations_start_at_no_experience_and_end_at_all() {
        assert_eq!(evaluation_points(1), vec![0, 1]);
        assert_eq!(evaluation_points(4), vec![0, 1, 2, 3, 4]);
        assert_eq!(evaluation_points(24), vec![0, 4, 8, 12, 16, 20, 24]);
        assert_eq!(evaluation_points(25), vec![0, 5, 10, 15, 20, 25]);
    }
}
