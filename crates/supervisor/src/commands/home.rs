use super::{load, rt_json, rt_lines, start};
use crate::cli::Common;
use crate::report::{self, Row};
use crate::session::Session;
use crate::shared::{AxisSnap, Control};
use motion_rt::termination as signals;
use std::time::{Duration, Instant};

/// `home`: the commissioning run of interface.md.
pub fn home(common: &Common, names: &[String], json: bool, parallel: bool, timeout_s: f64) -> i32 {
    let Some((m, source)) = load(common) else {
        return 2;
    };
    let mut order = Vec::new();
    for n in names {
        match m.axis_index(n) {
            Some(i) => order.push(i),
            None => {
                let known: Vec<&str> = m.axes.iter().map(|a| a.name.as_str()).collect();
                eprintln!(
                    "motion-supervisor: no axis '{n}' in {source} (axes: {})",
                    known.join(", ")
                );
                return 2;
            }
        }
    }
    if order.is_empty() {
        order = (0..m.axes.len()).collect();
    }
    let Some(mut session) = start(common, m, &[]) else {
        return 1;
    };
    eprintln!(
        "motion-supervisor: homing {} axis(es) of {source}{}",
        order.len(),
        if parallel {
            " in parallel"
        } else {
            " in config order"
        }
    );

    let mut notes: Vec<Option<String>> = vec![None; session.machine.axes.len()];
    let mut interrupted = None;
    let batches: Vec<Vec<usize>> = if parallel {
        vec![order.clone()]
    } else {
        order.iter().map(|&i| vec![i]).collect()
    };
    'batches: for batch in &batches {
        session.poll();
        let started_before: Vec<u32> = batch
            .iter()
            .map(|&i| snap_of(&session, i).homes_started)
            .collect();
        for &i in batch {
            let _ = session.send(Control::Home(i));
        }
        let deadline = Instant::now() + Duration::from_secs_f64(timeout_s);
        let mut stopped = false;
        loop {
            std::thread::sleep(Duration::from_millis(10));
            session.poll();
            let done = batch.iter().zip(&started_before).all(|(&i, &before)| {
                let s = snap_of(&session, i);
                s.homes_started > before && s.settled()
            });
            if done {
                break;
            }
            if let Some(sig) = signals::received() {
                interrupted = Some(sig);
                break 'batches;
            }
            if !stopped && Instant::now() > deadline {
                for &i in batch {
                    notes[i] = Some(format!("no result within --timeout {timeout_s} s: stopped"));
                    let _ = session.send(Control::Stop(i));
                }
                stopped = true;
            }
            if let Some(e) = session.check_alive() {
                // The engines notice the silence themselves (ERR 12/40) and
                // stop; keep following them until they have.
                if session.io.as_mut().is_some_and(|io| io.exited().is_some()) {
                    continue;
                }
                eprintln!("motion-supervisor: {e}");
                break 'batches;
            }
        }
    }
    if let Some(sig) = interrupted {
        eprintln!("motion-supervisor: signal {sig}: stopping every axis");
        // Stop what is in process and let it come to rest, so the result
        // shows how homing ended (ERR 12 / EXERR 1) before leaving.
        for &i in &order {
            let _ = session.send(Control::Stop(i));
        }
        let until = Instant::now() + Duration::from_secs(10);
        while Instant::now() < until {
            std::thread::sleep(Duration::from_millis(10));
            session.poll();
            let busy = order.iter().any(|&i| {
                let s = snap_of(&session, i);
                s.status.ip || s.status.stopping || s.cmd_velocity != 0.0
            });
            if !busy {
                break;
            }
        }
    }
    if let Some(e) = session.check_alive() {
        eprintln!("motion-supervisor: {e}");
    }

    // The result is the state when homing ended: leaving disables the drives
    // (a shutdown), which clears HomedStatus.
    session.poll();
    let result = session.snapshot.clone();
    let f = session.finish();
    let snap = result.as_deref().or(f.snapshot.as_deref());
    let rows: Vec<Row> = order
        .iter()
        .map(|&i| {
            let s = snap.map(|s| s.axes[i]).unwrap_or_default();
            let note = notes[i].clone().or_else(|| {
                (s.homes_started == 0).then(|| "not homed: the run ended before this axis".into())
            });
            Row::new(&f.machine.axes[i], s, note)
        })
        .collect();
    let summary = f.totals.summary();
    if json {
        let mut v = rt_json(&f);
        v["axes"] = rows.iter().map(Row::to_json).collect();
        v["latency"] = summary.to_json();
        println!("{v}");
    } else {
        print!("{}", report::table(&rows));
        println!();
        print!("{}", summary.table());
        for l in rt_lines(&f) {
            println!("{l}");
        }
    }
    if let Some(sig) = interrupted {
        return 128 + sig;
    }
    if rows.iter().all(|r| r.snap.status.pc) {
        0
    } else {
        1
    }
}

fn snap_of(session: &Session, i: usize) -> AxisSnap {
    session
        .snapshot
        .as_ref()
        .map(|s| s.axes[i])
        .unwrap_or_default()
}
