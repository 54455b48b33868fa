//! What a second thread can add on this machine, with nothing shared: the same
//! compute-bound loop (a logistic map, no memory traffic) timed on one thread, then on
//! two OS threads at once, round after round. The throughput ratio `2 * t1 / t2` is the
//! ceiling for any program's 1-vs-2-thread speed-up here; on a virtual machine whose two
//! vCPUs share a host core, or whose host is busy, it falls below 2.
//!
//! ```sh
//! cargo run --release --example two_threads -- [ROUNDS]
//! ```

use std::time::Instant;

/// About 0.75 s of dependent floating-point work on a 2 GHz core.
fn work(seed: u64) -> f64 {
    let mut x = 0.5 + seed as f64 * 1e-9;
    let mut sum = 0.0;
    for i in 0..100_000_000u64 {
        x = 3.9 * x * (1.0 - x);
        sum += x;
        if i & 0xffff == 0 {
            x = x.clamp(0.01, 0.99);
        }
    }
    sum
}

fn main() {
    let rounds: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(5);
    let mut ratios = Vec::new();
    for round in 0..rounds {
        let t = Instant::now();
        std::hint::black_box(work(1));
        let one = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let threads: Vec<_> = (0..2).map(|k| std::thread::spawn(move || std::hint::black_box(work(k + 2)))).collect();
        for h in threads {
            h.join().expect("worker thread");
        }
        let two = t.elapsed().as_secs_f64();
        let ratio = 2.0 * one / two;
        ratios.push(ratio);
        println!("round {round}: 1 thread {one:.3} s, 2 threads {two:.3} s: throughput ratio {ratio:.3}");
    }
    ratios.sort_by(f64::total_cmp);
    println!("median throughput ratio {:.3} over {rounds} rounds", ratios[ratios.len() / 2]);
}
