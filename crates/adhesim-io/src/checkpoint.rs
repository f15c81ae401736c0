//! Checkpoints: everything a run needs to continue bit for bit after it stopped.
//!
//! A checkpoint holds the stepper's [`Snapshot`] (time, step counter, u, v, the committed
//! contact state, the internal variables of viscoelastic materials, the current Δt and its
//! cut-back bookkeeping, the energy accumulators, the forces at the start of the next step
//! and the Delassus operator the Gauss-Seidel contact solve keeps for reuse), the resume
//! state of each output ([`crate::output::Observer::resume_state`], opaque here) and the
//! run's counters. It is tied to the problem it was written for by a fingerprint, so that
//! resuming with a changed scenario is refused.
//!
//! File format (`DIR/checkpoint.bin`, little-endian): the magic `ADHCKPT\0`, a format
//! version (u32), then length-prefixed fields (u64 counts, f64 bit patterns, UTF-8 strings),
//! and last an FNV-1a 64 checksum of everything before it. The file is replaced atomically
//! (see [`crate::output::atomic`]), so there is always one complete checkpoint: the last.

use crate::codec::{Codec, Dec, Enc};
use crate::output::settings::OutputSettings;
use crate::output::{
    saved_state, FrameProgress, HistoryObserver, SavedObserver, FRAMES_KEY, HISTORY_KEY,
};
use adhesim::contact::history::MAX_HISTORY_VALUES;
use adhesim::problem::Problem;
use adhesim::time::{CachedDelassus, DelassusCache, SiteContact, Snapshot};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// File name of the checkpoint in a run's output directory.
pub const FILE_NAME: &str = "checkpoint.bin";

const MAGIC: &[u8; 8] = b"ADHCKPT\0";
/// The checkpoint format this version writes.
pub const FORMAT: u32 = 7;
/// The first format with the observers' own resume states ([`SavedObserver`]).
const FORMAT_OBSERVER_STATES: u32 = 7;
/// The previous format, still read and resumed (its fingerprint is this build's): the frame
/// writer's progress and the rows of history.csv in fixed fields where the observers' states
/// are now.
const FORMAT_FIXED_OUTPUTS: u32 = 6;
/// The format before, still read: the layout of format 6, written by builds whose
/// fingerprint hashed the output settings as part of the problem (so their fingerprints
/// differ from this build's for the same scenario).
#[cfg_attr(not(test), allow(dead_code))]
const FORMAT_OUTPUT_IN_PROBLEM: u32 = 5;
/// The format before that, still read: it stored the RCC law's history (β, u_t, D), the only
/// law then, among each contact node's other values.
const FORMAT_RCC_ONLY: u32 = 4;

/// A run's state after a committed step.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoint {
    /// adhesim version that wrote it.
    pub version: String,
    /// [`fingerprint`] of the problem.
    pub fingerprint: u64,
    /// The file format it was read from ([`FORMAT`] for one written by this version).
    pub format: u32,
    /// The stepper's state.
    pub snapshot: Snapshot,
    /// The resume state of each of the run's observers ([`crate::output::Observer`]).
    pub observers: Vec<SavedObserver>,
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

/// A fingerprint of everything that defines a run: `problem` (meshes, materials, loads,
/// contact pairs, time stepping) and `output` (tracks, frames, maps, reactions' names):
/// FNV-1a 64 of their `Debug` forms, in which every number appears in shortest round-trip
/// form.
pub fn fingerprint(problem: &Problem, output: &OutputSettings) -> u64 {
    let mut h = Fnv::new();
    let _ = write!(h, "{problem:?}");
    let _ = write!(h, "{output:?}");
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
    pub fn write(self, dir: &Path) -> Result<(), CheckpointError> {
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

    /// The resume state saved by the observer whose key is `key`, if any.
    pub fn observer_state(&self, key: &str) -> Option<&[u8]> {
        saved_state(&self.observers, key)
    }

    /// Checks that the checkpoint in `dir` was written by this version for the run whose
    /// [`fingerprint`] is `fingerprint`.
    pub fn check_matches(&self, fingerprint: u64, dir: &Path) -> Result<(), CheckpointError> {
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
        if self.fingerprint != fingerprint {
            // The fingerprint hashes the problem as this build describes it; the builds that
            // wrote an older format described the same scenario differently, so a mismatch
            // there says nothing about the scenario.
            let reason = if self.format < FORMAT_FIXED_OUTPUTS {
                format!(
                    "it was written in checkpoint format {} by an earlier build of adhesim \
                     {version}, whose description of a scenario differs from this build's \
                     even when the scenario file is the same; finish the run with the build \
                     that started it, or start it again (this build resumes checkpoints of \
                     formats {FORMAT_FIXED_OUTPUTS} and {FORMAT})",
                    self.format
                )
            } else {
                "the scenario differs from the one the run was started with (meshes, \
                 materials, loads, contact, time stepping, tracks or output settings changed); \
                 resume with the unchanged scenario, or start a new run in another directory"
                    .into()
            };
            return Err(mismatch(reason));
        }
        Ok(())
    }

    /// The checkpoint as bytes (see the module documentation for the layout). It takes the
    /// checkpoint by value: [`Checkpoint::visit`], which reading shares, needs its fields
    /// mutable, and the caller has no further use for them.
    pub fn encode(self) -> Vec<u8> {
        self.encode_as(FORMAT)
    }

    /// [`Checkpoint::encode`] in the file format `format` ([`FORMAT`], or an older one for the
    /// tests that read it).
    fn encode_as(mut self, format: u32) -> Vec<u8> {
        let mut w = Enc(Vec::new());
        w.0.extend_from_slice(MAGIC);
        w.0.extend_from_slice(&format.to_le_bytes());
        self.visit(&mut w, format)
            .expect("writing to memory cannot fail");
        let mut h = Fnv::new();
        h.update(&w.0);
        w.0.extend_from_slice(&h.0.to_le_bytes());
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
        if !(FORMAT_RCC_ONLY..=FORMAT).contains(&format) {
            return Err(format!(
                "format {format}, but this version of adhesim reads formats \
                 {FORMAT_RCC_ONLY} to {FORMAT}"
            ));
        }
        let mut checkpoint = Checkpoint {
            version: String::new(),
            fingerprint: 0,
            format,
            snapshot: Snapshot {
                t: 0.0,
                step: 0,
                u: Vec::new(),
                v: Vec::new(),
                dt: 0.0,
                good_steps_since_cut: 0,
                f_ext0: Vec::new(),
                f_int0: Vec::new(),
                external_work: 0.0,
                last_internal: 0.0,
                contact: Vec::new(),
                material_history: Vec::new(),
                delassus: None,
            },
            observers: Vec::new(),
            cutbacks: 0,
            newton_iterations: 0,
            wall_time: 0.0,
        };
        checkpoint.visit(&mut r, format)?;
        r.finish()?;
        Ok(checkpoint)
    }

    /// Every field after the header, in file order, through `c`: the one list of fields that
    /// both writing and reading follow. `format` is the file's (always [`FORMAT`] when
    /// writing).
    fn visit(&mut self, c: &mut impl Codec, format: u32) -> Result<(), String> {
        c.str(&mut self.version)?;
        c.u64(&mut self.fingerprint)?;
        let s = &mut self.snapshot;
        c.f64(&mut s.t)?;
        c.usize(&mut s.step)?;
        c.f64s(&mut s.u)?;
        c.f64s(&mut s.v)?;
        c.f64(&mut s.dt)?;
        c.usize(&mut s.good_steps_since_cut)?;
        c.f64s(&mut s.f_ext0)?;
        c.f64s(&mut s.f_int0)?;
        c.f64(&mut s.external_work)?;
        c.f64(&mut s.last_internal)?;
        c.count(&mut s.contact, 8)?;
        for nodes in &mut s.contact {
            if format == FORMAT_RCC_ONLY {
                rcc_only_nodes(c, nodes)?;
                continue;
            }
            // Per pair: how many history values each node holds, then per node its values,
            // its state code and its history.
            let mut stored = MAX_HISTORY_VALUES;
            c.usize(&mut stored)?;
            if stored > MAX_HISTORY_VALUES {
                return Err(format!(
                    "{stored} history values per contact node, more than the \
                     {MAX_HISTORY_VALUES} this version of adhesim holds"
                ));
            }
            c.count(nodes, 8 * (SiteContact::VALUES + stored) + 4)?;
            for node in nodes.iter_mut() {
                let mut values = node.to_values();
                for x in &mut values {
                    c.f64(x)?;
                }
                let mut state = node.state;
                c.i32(&mut state)?;
                let mut history = node.history;
                for x in &mut history.0[..stored] {
                    c.f64(x)?;
                }
                *node = SiteContact::from_values(&values, state, history);
            }
        }
        c.f64s(&mut s.material_history)?;
        delassus(c, &mut s.delassus)?;
        if format >= FORMAT_OBSERVER_STATES {
            c.count(&mut self.observers, 16)?;
            for o in &mut self.observers {
                c.str(&mut o.key)?;
                c.bytes(&mut o.state)?;
            }
        } else {
            legacy_observers(c, &mut self.observers)?;
        }
        c.usize(&mut self.cutbacks)?;
        c.usize(&mut self.newton_iterations)?;
        c.f64(&mut self.wall_time)
    }
}

/// The observers' states as formats 4 to 6 held them: the frame writer's progress inline,
/// then the rows of history.csv; the contact maps kept none (they resume from the time).
fn legacy_observers(c: &mut impl Codec, observers: &mut Vec<SavedObserver>) -> Result<(), String> {
    let mut frames = match saved_state(observers, FRAMES_KEY) {
        Some(s) => FrameProgress::from_bytes(s)?,
        None => FrameProgress::default(),
    };
    let mut rows = match saved_state(observers, HISTORY_KEY) {
        Some(s) => HistoryObserver::rows_in_state(s)?,
        None => 0,
    };
    frames.visit(c)?;
    c.u64(&mut rows)?;
    *observers = vec![
        SavedObserver {
            key: FRAMES_KEY.into(),
            state: frames.to_bytes(),
        },
        SavedObserver {
            key: HISTORY_KEY.into(),
            state: HistoryObserver::state_of_rows(rows),
        },
    ];
    Ok(())
}

/// The contact nodes of a pair in format 4: per node β, u_t (3), then the
/// [`SiteContact::to_values`], then D, then the state code. β, u_t and D are the first five
/// values of the RCC law's history ([`adhesim::contact::RccHistory`]), in its order.
fn rcc_only_nodes(c: &mut impl Codec, nodes: &mut Vec<SiteContact>) -> Result<(), String> {
    c.count(nodes, 8 * (SiteContact::VALUES + 5) + 4)?;
    for node in nodes.iter_mut() {
        let mut history = node.history;
        let mut values = node.to_values();
        for x in history.0[..4].iter_mut().chain(&mut values) {
            c.f64(x)?;
        }
        c.f64(&mut history.0[4])?;
        let mut state = node.state;
        c.i32(&mut state)?;
        *node = SiteContact::from_values(&values, state, history);
    }
    Ok(())
}

/// The kept Delassus operator: a count (0 or 1), then its key, its frames and W.
fn delassus(c: &mut impl Codec, cache: &mut DelassusCache) -> Result<(), String> {
    let mut present = usize::from(cache.is_some());
    c.usize(&mut present)?;
    match present {
        0 => {
            *cache = None;
            return Ok(());
        }
        1 => {}
        _ => return Err("more than one Delassus operator".into()),
    }
    let d = cache.get_or_insert_with(CachedDelassus::default);
    c.count(&mut d.key, 8)?;
    d.key.iter_mut().try_for_each(|k| c.u64(k))?;
    c.count(&mut d.frames, 72)?;
    for x in d.frames.iter_mut().flatten().flatten() {
        c.f64(x)?;
    }
    c.usize(&mut d.w.m)?;
    c.f64s(&mut d.w.w)?;
    if d.w.w.len() != d.w.m * d.w.m || d.w.m != 3 * d.frames.len() {
        return Err("the Delassus operator's sizes do not agree".into());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::vtk::PvdEntry;
    use adhesim::contact::LawHistory;

    fn sample() -> Checkpoint {
        let c = SiteContact {
            history: adhesim::contact::RccHistory {
                beta: 0.25,
                ut: [1e-9, -2e-9, 0.0],
                damage: 0.125,
            }
            .encode(),
            r_dry: [0.1, 0.2, -0.3],
            r_adh: [0.0, 0.0, 4.5],
            force: [1.0, 2.0, 3.0],
            gap: f64::NAN,
            slip: [1e-300, -0.0],
            state: 3,
            tangent_axes: [[1.0, 0.0, 0.0], [0.0, 1.0 / 3.0, 0.7]],
        };
        Checkpoint {
            version: env!("CARGO_PKG_VERSION").into(),
            fingerprint: 0x1234_5678_9abc_def0,
            format: FORMAT,
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
                contact: vec![vec![c, SiteContact::default()], vec![]],
                material_history: vec![0.25, -1e-9],
                delassus: Some(CachedDelassus {
                    key: vec![7, u64::MAX],
                    frames: vec![[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -0.5]]],
                    w: adhesim::contact::solver::gauss_seidel::delassus::Delassus {
                        w: (0..9).map(|i| i as f64 * 1e-7).collect(),
                        m: 3,
                    },
                }),
            },
            observers: vec![
                SavedObserver {
                    key: FRAMES_KEY.into(),
                    state: FrameProgress {
                        frames: 3,
                        next_time: 0.30000000000000004,
                        entries: vec![PvdEntry {
                            time: 0.0,
                            file: "vtu/é_00000.vtu".into(),
                        }],
                    }
                    .to_bytes(),
                },
                SavedObserver {
                    key: HISTORY_KEY.into(),
                    state: HistoryObserver::state_of_rows(8),
                },
            ],
            cutbacks: 2,
            newton_iterations: 31,
            wall_time: 1.25,
        }
    }

    fn bits_equal(a: &Checkpoint, b: &Checkpoint) -> bool {
        // NaN != NaN, so compare the encodings.
        a.clone().encode() == b.clone().encode()
    }

    #[test]
    fn round_trip_is_bit_exact() {
        let c = sample();
        let bytes = c.clone().encode();
        let d = Checkpoint::decode(&bytes).unwrap();
        assert!(bits_equal(&c, &d));
        assert!(d.snapshot.contact[0][0].gap.is_nan());
        assert_eq!(d.snapshot.contact[0][0].tangent_axes[1][1], 1.0 / 3.0);
        assert_eq!(d.snapshot.u[1].to_bits(), (-0.0f64).to_bits());
        let frames = FrameProgress::from_bytes(&d.observers[0].state).unwrap();
        assert_eq!(frames.entries[0].file, "vtu/é_00000.vtu");
        assert_eq!(HistoryObserver::rows_in_state(&d.observers[1].state), Ok(8));
    }

    /// An observer's state is carried as it is, whatever it holds: the checkpoint does not
    /// read it.
    #[test]
    fn any_observer_state_round_trips() {
        let mut c = sample();
        c.observers.push(SavedObserver {
            key: "probe".into(),
            state: vec![0, 255, 7],
        });
        c.observers.push(SavedObserver::default());
        let d = Checkpoint::decode(&c.clone().encode()).unwrap();
        assert_eq!(d.observers, c.observers);
    }

    /// Format 6 held the frame writer's progress and the history's rows in fixed fields; it
    /// is read into the same observer states (the maps, which it did not hold, resume from
    /// the time), and its fingerprint is this build's, so such a run goes on.
    #[test]
    fn format_6_is_read_into_observer_states() {
        let c = sample();
        let six = c.clone().encode_as(FORMAT_FIXED_OUTPUTS);
        assert_eq!(&six[8..12], &6u32.to_le_bytes());
        assert_ne!(six, c.clone().encode());
        let d = Checkpoint::decode(&six).unwrap();
        assert_eq!(d.format, FORMAT_FIXED_OUTPUTS);
        assert_eq!(d.observers, c.observers);
        assert!(d.check_matches(c.fingerprint, Path::new("out")).is_ok());
    }

    /// Format 4 (the RCC law's history among the node's values) is still read, to the same
    /// checkpoint.
    #[test]
    fn format_4_is_read() {
        let c = sample();
        let old = c.clone().encode_as(FORMAT_RCC_ONLY);
        assert_eq!(&old[8..12], &4u32.to_le_bytes());
        assert_ne!(old, c.clone().encode());
        let d = Checkpoint::decode(&old).unwrap();
        assert!(bits_equal(&c, &d));
        let h = adhesim::contact::RccHistory::decode(&d.snapshot.contact[0][0].history);
        assert_eq!((h.beta, h.ut, h.damage), (0.25, [1e-9, -2e-9, 0.0], 0.125));
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
        let time = adhesim::problem::TimeSettings::default();
        let problem = |t_end: f64| Problem {
            name: "p".into(),
            bodies: vec![],
            dirichlet: vec![],
            loads: vec![],
            gravity: Default::default(),
            time: adhesim::problem::TimeSettings {
                t_end,
                ..time.clone()
            },
            contacts: vec![],
        };
        let output = |frame_interval: f64| OutputSettings {
            frame_interval,
            ..Default::default()
        };
        let out = output(0.1);
        assert_eq!(
            fingerprint(&problem(1.0), &out),
            fingerprint(&problem(1.0), &out)
        );
        assert_ne!(
            fingerprint(&problem(1.0), &out),
            fingerprint(&problem(1.0000000000000002), &out)
        );
        // What the run writes is part of it too (a resumed run must write the same columns).
        assert_ne!(
            fingerprint(&problem(1.0), &out),
            fingerprint(&problem(1.0), &output(0.2))
        );
        // A checkpoint for another problem: a changed scenario in the current format, an
        // earlier build in the older one (it cannot tell the two apart, so it says so).
        let dir = Path::new("out/p");
        let refusal = |c: &Checkpoint| {
            c.check_matches(fingerprint(&problem(1.0), &out), dir)
                .unwrap_err()
                .to_string()
        };
        let current = Checkpoint::decode(&sample().encode()).unwrap();
        let err = refusal(&current);
        assert!(err.contains("the scenario differs"), "{err}");
        let older = Checkpoint::decode(&sample().encode_as(FORMAT_RCC_ONLY)).unwrap();
        assert_eq!(older.format, FORMAT_RCC_ONLY);
        let err = refusal(&older);
        assert!(
            err.contains("checkpoint format 4 by an earlier build"),
            "{err}"
        );
        assert!(err.contains("out/p/checkpoint.bin"), "{err}");
        // Format 5 has format 6's layout but hashed the output settings inside the problem.
        let five = Checkpoint::decode(&sample().encode_as(FORMAT_OUTPUT_IN_PROBLEM)).unwrap();
        assert!(
            five.clone().encode() == current.clone().encode(),
            "same fields"
        );
        let err = refusal(&five);
        assert!(
            err.contains("checkpoint format 5 by an earlier build"),
            "{err}"
        );
        let mut same = older.clone();
        same.fingerprint = fingerprint(&problem(1.0), &out);
        assert!(same
            .check_matches(fingerprint(&problem(1.0), &out), dir)
            .is_ok());
    }
}
