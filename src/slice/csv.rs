//! The per-layer table: one row per layer — `z` (mid-height along the build direction, mm),
//! `thickness` (mm), `area` (mm², holes subtracted), `perimeter` (mm), `loops`, `holes`.

use super::{Section, Stack, StackWriter};
use crate::error::Result;
use crate::io::atomic::AtomicFile;
use std::path::Path;

/// Writes the CSV table.
pub struct CsvWriter {
    file: AtomicFile,
    stack: Stack,
}

impl CsvWriter {
    /// Starts `path` with the header row.
    pub fn create(path: &Path, stack: &Stack) -> Result<CsvWriter> {
        let mut file = AtomicFile::create(path)?;
        file.write(b"z,thickness,area,perimeter,loops,holes\n")?;
        Ok(CsvWriter {
            file,
            stack: stack.clone(),
        })
    }
}

impl StackWriter for CsvWriter {
    fn encode(&self, index: usize, section: &Section) -> Result<Vec<u8>> {
        let l = self.stack.layers[index];
        let m = section.measures();
        Ok(format!(
            "{:.6},{:.6},{:.6},{:.6},{},{}\n",
            l.z, l.thickness, m.area, m.perimeter, m.loops, m.holes
        )
        .into_bytes())
    }

    fn put(&mut self, _index: usize, encoded: Vec<u8>) -> Result<()> {
        self.file.write(&encoded)
    }

    fn finish(self: Box<Self>) -> Result<()> {
        self.file.commit()
    }
}
