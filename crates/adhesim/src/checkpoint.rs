//! Checkpoints: everything a run needs to continue bit for bit after it stopped.
//!
//! A checkpoint holds the stepper's [`Snapshot`] (time, step counter, u, v, the committed
//! contact state, the internal variables of viscoelastic materials, the current Δt and its
//! cut-back bookkeeping, the energy accumulators and the forces at the start of the next
//! step), how far the outputs got (frames written, the next frame time, the PVD entries,
//! history rows) and the run's counters. It is tied to the problem it was written for by a
//! fingerprint, so that resuming with a changed scenario is refused.
//!
//! File format (`DIR/checkpoint.bin`, little-endian): the magic `ADHCKPT\0`, a format
//! version (u32), then length-prefixed fields (u64 counts, f64 bit patterns, UTF-8 strings),
//! and last an FNV-1a 64 checksum of everything before it. The file is replaced atomically
//! (see [`crate::output::atomic`]), so there is always one complete checkpoint: the last.

use crate::output::vtk::PvdEntry;
use crate::output::FrameProgress;
use crate::problem::Problem;
use crate::time::{NodeContact, Snapshot};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// File name of the checkpoint in a run's output directory.
pub const FILE_NAME: &str = "checkpoint.bin";

const MAGIC: &[u8; 8] = b"ADHCKPT\0";
const FORMAT: u32 = 3;

/// A run's state after a committed step.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoint {
    /// adhesim version that wrote it.
    pub version: String,
    /// [`fingerprint`] of the problem.
    pub fingerprint: u64,
    /// The stepper's state.
    pub snapshot: Snapshot,
    /// How far the frame writer got.
    pub frames: FrameProgress,
    /// Rows of history.csv written (the row at t = 0 included).
    pub history_rows: u64,
    /// Discarded attempts so far.
    pub cutbacks: usize,
    /// Newton iterations so far.
    pub newton_iterations: usize,
    /// Wall-clock time spent up to the checkpoint [s].
    pub wall_time: f64,
}

/// Why a checkpoint cannot be written, read or used.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    /// The file could not be read or written.
    #[error("checkpoint {path}: {source}")]
    Io {
        /// The checkpoint file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file is not a complete checkpoint.
    #[error("checkpoint {path} is damaged or not a checkpoint: {reason}")]
    Corrupt {
        /// The checkpoint file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The checkpoint belongs to another problem or another version of adhesim.
    #[error("cannot resume from {path}: {reason}")]
    Mismatch {
        /// The checkpoint file.
        path: PathBuf,
        /// What differs.
        reason: String,
    },
}

/// A fingerprint of everything that defines `problem` (meshes, materials, loads, contact
/// pairs, time stepping, tracks, output settings): FNV-1a 64 of its `Debug` form, in which
/// every number appears in shortest round-trip form.
pub fn fingerprint(problem: &Problem) -> u64 {
    let mut h = Fnv::new();
    let _ = write!(h, "{problem:?}");
    h.0
}

/// FNV-1a 64, also a `fmt::Write` sink so large `Debug` forms are hashed without a copy.
struct Fnv(u64);

impl Fnv {
    fn new() -> Self {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
    fn update(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
}

impl std::fmt::Write for Fnv {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        self.update(s.as_bytes());
        Ok(())
    }
}

impl Checkpoint {
    /// Path of the checkpoint in the output directory `dir`.
    pub fn path(dir: &Path) -> PathBuf {
        dir.join(FILE_NAME)
    }

    /// Writes the checkpoint to `DIR/checkpoint.bin`, replacing the previous one atomically.
    pub fn write(&self, dir: &Path) -> Result<(), CheckpointError> {
        let path = Self::path(dir);
        crate::output::atomic::write_atomic(&path, &self.encode())
            .map_err(|source| CheckpointError::Io { path, source })
    }

    /// Reads `DIR/checkpoint.bin`.
    pub fn read(dir: &Path) -> Result<Self, CheckpointError> {
        let path = Self::path(dir);
        let bytes = std::fs::read(&path).map_err(|source| CheckpointError::Io {
            path: path.clone(),
            source,
        })?;
        Self::decode(&bytes).map_err(|reason| CheckpointError::Corrupt { path, reason })
    }

    /// Checks that the checkpoint in `dir` was written for `problem` by this version.
    pub fn check_matches(&self, problem: &Problem, dir: &Path) -> Result<(), CheckpointError> {
        let mismatch = |reason: String| CheckpointError::Mismatch {
            path: Self::path(dir),
            reason,
        };
        let version = env!("CARGO_PKG_VERSION");
        if self.version != version {
            return Err(mismatch(format!(
                "it was written by adhesim {} and this is adhesim {version}; finish the run \
                 with the version that started it, or start it again",
                self.version
            )));
        }
        if self.fingerprint != fingerprint(problem) {
            return Err(mismatch(
                "the scenario differs from the one the run was started with (meshes, \
                 materials, loads, contact, time stepping, tracks or output settings changed); \
                 resume with the unchanged scenario, or start a new run in another directory"
                    .into(),
            ));
        }
        Ok(())
    }

    /// The checkpoint as bytes (see the module documentation for the layout).
    pub fn encode(&self) -> Vec<u8> {
        let mut w = Enc(Vec::new());
        w.0.extend_from_slice(MAGIC);
        w.0.extend_from_slice(&FORMAT.to_le_bytes());
        w.str(&self.version);
        w.u64(self.fingerprint);
        let Snapshot {
            t,
            step,
            u,
            v,
            dt,
            good_steps_since_cut,
            f_ext0,
            f_int0,
            external_work,
            last_internal,
            contact,
            material_history,
        } = &self.snapshot;
        w.f64(*t);
        w.usize(*step);
        w.f64s(u);
        w.f64s(v);
        w.f64(*dt);
        w.usize(*good_steps_since_cut);
        w.f64s(f_ext0);
        w.f64s(f_int0);
        w.f64(*external_work);
        w.f64(*last_internal);
        w.usize(contact.len());
        for nodes in contact {
            w.usize(nodes.len());
            for c in nodes {
                c.to_values().iter().for_each(|x| w.f64(*x));
                w.0.extend_from_slice(&c.state.to_le_bytes());
            }
        }
        w.f64s(material_history);
        let FrameProgress {
            frames,
            next_time,
            entries,
        } = &self.frames;
        w.usize(*frames);
        w.f64(*next_time);
        w.usize(entries.len());
        for e in entries {
            w.f64(e.time);
            w.str(&e.file);
        }
        w.u64(self.history_rows);
        w.usize(self.cutbacks);
        w.usize(self.newton_iterations);
        w.f64(self.wall_time);
        let mut h = Fnv::new();
        h.update(&w.0);
        w.u64(h.0);
        w.0
    }

    /// Parses bytes written by [`Checkpoint::encode`]; Err says what is wrong.
    pub fn decode(bytes: &[u8]) -> Result<Self, String> {
        if bytes.len() < MAGIC.len() + 4 + 8 || &bytes[..MAGIC.len()] != MAGIC {
            return Err("it does not start with an adhesim checkpoint header".into());
        }
        let (body, sum) = bytes.split_at(bytes.len() - 8);
        let mut h = Fnv::new();
        h.update(body);
        if h.0.to_le_bytes() != sum {
            return Err("its checksum does not match (truncated or modified file)".into());
        }
        let mut r = Dec {
            bytes: body,
            pos: MAGIC.len(),
        };
        let format = u32::from_le_bytes(r.take(4)?.try_into().unwrap());
        if format != FORMAT {
            return Err(format!(
                "format {format}, but this version of adhesim reads format {FORMAT}"
            ));
        }
        let version = r.str()?;
        let fingerprint = r.u64()?;
        let t = r.f64()?;
        let step = r.usize()?;
        let u = r.f64s()?;
        let v = r.f64s()?;
        let dt = r.f64()?;
        let good_steps_since_cut = r.usize()?;
        let f_ext0 = r.f64s()?;
        let f_int0 = r.f64s()?;
        let external_work = r.f64()?;
        let last_internal = r.f64()?;
        let pairs = r.len(8)?;
        let mut contact = Vec::with_capacity(pairs);
        for _ in 0..pairs {
            let n = r.len(8 * NodeContact::VALUES + 4)?;
            let mut nodes = Vec::with_capacity(n);
            for _ in 0..n {
                let mut x = [0.0; NodeContact::VALUES];
                for xi in &mut x {
                    *xi = r.f64()?;
                }
                let state = i32::from_le_bytes(r.take(4)?.try_into().unwrap());
                nodes.push(NodeContact::from_values(&x, state));
            }
            contact.push(nodes);
        }
        let material_history = r.f64s()?;
        let frames = r.usize()?;
        let next_time = r.f64()?;
        let n_entries = r.len(16)?;
        let mut entries = Vec::with_capacity(n_entries);
        for _ in 0..n_entries {
            let time = r.f64()?;
            let file = r.str()?;
            entries.push(PvdEntry { time, file });
        }
        let history_rows = r.u64()?;
        let cutbacks = r.usize()?;
        let newton_iterations = r.usize()?;
        let wall_time = r.f64()?;
        if r.pos != body.len() {
            return Err(format!(
                "{} unexpected bytes after the last field",
                body.len() - r.pos
            ));
        }
        Ok(Checkpoint {
            version,
            fingerprint,
            snapshot: Snapshot {
                t,
                step,
                u,
                v,
                dt,
                good_steps_since_cut,
                f_ext0,
                f_int0,
                external_work,
                last_internal,
                contact,
                material_history,
            },
            frames: FrameProgress {
                frames,
                next_time,
                entries,
            },
            history_rows,
            cutbacks,
            newton_iterations,
            wall_time,
        })
    }
}

struct Enc(Vec<u8>);

impl Enc {
    fn u64(&mut self, x: u64) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    fn usize(&mut self, x: usize) {
        self.u64(x as u64);
    }
    fn f64(&mut self, x: f64) {
        self.u64(x.to_bits());
    }
    fn f64s(&mut self, x: &[f64]) {
        self.usize(x.len());
        self.0.reserve(8 * x.len());
        for v in x {
            self.f64(*v);
        }
    }
    fn str(&mut self, s: &str) {
        self.usize(s.len());
        self.0.extend_from_slice(s.as_bytes());
    }
}

struct Dec<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl Dec<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8], String> {
        if self.bytes.len() - self.pos < n {
            return Err(format!("it ends early (at byte {})", self.pos));
        }
        let s = &self.bytes[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }
    fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into().unwrap()))
    }
    fn usize(&mut self) -> Result<usize, String> {
        usize::try_from(self.u64()?).map_err(|_| "a count does not fit in memory".to_string())
    }
    /// A count of items of at least `item_bytes` bytes each, checked against what is left.
    fn len(&mut self, item_bytes: usize) -> Result<usize, String> {
        let n = self.usize()?;
        if n.saturating_mul(item_bytes) > self.bytes.len() - self.pos {
            return Err(format!("a count ({n}) exceeds the file's size"));
        }
        Ok(n)
    }
    fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_bits(self.u64()?))
    }
    fn f64s(&mut self) -> Result<Vec<f64>, String> {
        let n = self.len(8)?;
        (0..n).map(|_| self.f64()).collect()
    }
    fn str(&mut self) -> Result<String, String> {
        let n = self.len(1)?;
        String::from_utf8(self.take(n)?.to_vec()).map_err(|_| "a name is not UTF-8".to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Checkpoint {
        let c = NodeContact {
            beta: 0.25,
            ut: [1e-9, -2e-9, 0.0],
            r_dry: [0.1, 0.2, -0.3],
            r_adh: [0.0, 0.0, 4.5],
            force: [1.0, 2.0, 3.0],
            gap: f64::NAN,
            slip: [1e-300, -0.0],
            state: 3,
            tangent_axes: [[1.0, 0.0, 0.0], [0.0, 1.0 / 3.0, 0.7]],
            damage: 0.125,
        };
        Checkpoint {
            version: "0.1.0".into(),
            fingerprint: 0x1234_5678_9abc_def0,
            snapshot: Snapshot {
                t: 0.1 + 0.2,
                step: 7,
                u: vec![1.0 / 3.0, -0.0, 5e-324, f64::MAX],
                v: vec![0.1, 0.2, 0.3, 0.4],
                dt: 0.005,
                good_steps_since_cut: 1,
                f_ext0: vec![0.0; 4],
                f_int0: vec![-1.5; 4],
                external_work: 2.0,
                last_internal: 1.0,
                contact: vec![vec![c, NodeContact::default()], vec![]],
                material_history: vec![0.25, -1e-9],
            },
            frames: FrameProgress {
                frames: 3,
                next_time: 0.30000000000000004,
                entries: vec![PvdEntry {
                    time: 0.0,
                    file: "vtu/é_00000.vtu".into(),
                }],
            },
            history_rows: 8,
            cutbacks: 2,
            newton_iterations: 31,
            wall_time: 1.25,
        }
    }

    fn bits_equal(a: &Checkpoint, b: &Checkpoint) -> bool {
        // NaN != NaN, so compare the encodings.
        a.encode() == b.encode()
    }

    #[test]
    fn round_trip_is_bit_exact() {
        let c = sample();
        let bytes = c.encode();
        let d = Checkpoint::decode(&bytes).unwrap();
        assert!(bits_equal(&c, &d));
        assert!(d.snapshot.contact[0][0].gap.is_nan());
        assert_eq!(d.snapshot.contact[0][0].tangent_axes[1][1], 1.0 / 3.0);
        assert_eq!(d.snapshot.u[1].to_bits(), (-0.0f64).to_bits());
        assert_eq!(d.frames.entries[0].file, "vtu/é_00000.vtu");
    }

    #[test]
    fn damage_is_detected() {
        let bytes = sample().encode();
        for cut in [0, 5, 20, bytes.len() / 2, bytes.len() - 1] {
            assert!(Checkpoint::decode(&bytes[..cut]).is_err(), "cut at {cut}");
        }
        let mut flipped = bytes.clone();
        flipped[40] ^= 1;
        let err = Checkpoint::decode(&flipped).unwrap_err();
        assert!(err.contains("checksum"), "{err}");
        assert!(Checkpoint::decode(b"not a checkpoint at all, just text").is_err());
    }

    #[test]
    fn fingerprint_sees_a_changed_number() {
        let time = crate::problem::TimeSettings::default();
        let problem = |t_end: f64| Problem {
            name: "p".into(),
            bodies: vec![],
            dirichlet: vec![],
            loads: vec![],
            gravity: Default::default(),
            time: crate::problem::TimeSettings {
                t_end,
                ..time.clone()
            },
            contacts: vec![],
            tracks: vec![],
            output: crate::problem::OutputSettings {
                frame_interval: 0.1,
                ..Default::default()
            },
        };
        assert_eq!(fingerprint(&problem(1.0)), fingerprint(&problem(1.0)));
        assert_ne!(
            fingerprint(&problem(1.0)),
            fingerprint(&problem(1.0000000000000002))
        );
    }
}
