//! What the benchmarks share: the process's peak memory, and a sink that makes STL records
//! and drops them (the writing of a part too large for this machine's disk, without the disk).
#![allow(dead_code)]

use latvox::io::sink::{MeshSink, Triangle};

/// The process's peak resident memory, MB (`VmHWM`).
pub fn peak_rss_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

/// Binary STL records made for every triangle (normal, corners, attribute: 50 bytes each) and
/// dropped: the writing of a part too large for this machine's disk, without the disk.
#[derive(Default)]
pub struct DiscardedStl {
    pub triangles: u64,
    buf: Vec<u8>,
}

impl MeshSink for DiscardedStl {
    fn begin(&mut self, _: Option<u64>) -> latvox::Result<()> {
        Ok(())
    }
    fn triangles(&mut self, batch: &[Triangle]) -> latvox::Result<()> {
        self.buf.clear();
        for t in batch {
            let u = [0, 1, 2].map(|a| t[1][a] - t[0][a]);
            let v = [0, 1, 2].map(|a| t[2][a] - t[0][a]);
            let n = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            for x in n.iter().chain(t.iter().flatten()) {
                self.buf.extend_from_slice(&x.to_le_bytes());
            }
            self.buf.extend_from_slice(&[0, 0]);
        }
        self.triangles += batch.len() as u64;
        std::hint::black_box(&self.buf);
        Ok(())
    }
    fn finish(&mut self) -> latvox::Result<()> {
        Ok(())
    }
}
