//! The render state file: a render's exact fixed-point sums with the samples every row holds
//! and a fingerprint of what was rendered. Checkpoints, resumed renders, shards and merges
//! all go through it; `docs/state-format.md` describes the bytes.

use std::ops::Range;

use pathlight_scene::settings::check_resolution;
use pathlight_scene::{Camera, RenderSettings, Sampler};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::accumulation::{Accumulation, SampleCursor};
use crate::film::Film;
use crate::gpu_types::{GpuAccumPixel, GpuAovPixel, GpuCamera};
use crate::prepared::PreparedScene;

/// The first bytes of every state file.
pub const MAGIC: &[u8; 16] = b"pathlight-state\n";
/// The format version this build reads and writes.
pub const VERSION: u32 = 2;
/// Names of the auxiliary images a state holds when it holds them (in file order).
pub const AOV_NAMES: [&str; 2] = ["albedo", "normal"];
/// Bytes of the checksum that ends the file (SHA-256).
const CHECKSUM: usize = 32;
/// Bytes before the header: magic, version, header length.
const PREAMBLE: usize = 24;

/// What was rendered, apart from which samples: two states with equal fingerprints hold
/// samples of the same estimator and merge exactly. The backend is not part of it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Fingerprint {
    /// SHA-256 of the prepared scene (geometry, BVH, textures, materials, lights,
    /// environment): the scene file and its assets by content.
    pub scene: String,
    /// SHA-256 of the camera (position, orientation, field of view).
    pub camera: String,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Seed of the random sequence.
    pub seed: u32,
    /// Sample generator.
    pub sampler: String,
    /// Maximum path length in segments.
    pub max_depth: u32,
    /// Depth from which Russian roulette applies.
    pub rr_depth: u32,
    /// The auxiliary images accumulated with the colour: [`AOV_NAMES`], or none.
    pub aovs: Vec<String>,
}

/// SHA-256 of `parts` in turn, as lowercase hex.
fn sha256_hex(parts: &[&[u8]]) -> String {
    let mut hasher = Sha256::new();
    for part in parts {
        hasher.update((part.len() as u64).to_le_bytes());
        hasher.update(part);
    }
    hasher
        .finalize()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

impl Fingerprint {
    /// The fingerprint of rendering as `camera` sees it with `settings`, without the scene's
    /// hash (`scene` empty): for a render that neither reads nor writes a state, since
    /// hashing a large scene's buffers is a noticeable part of its first frame. A state
    /// holding one must not be written: it would merge with any scene's.
    pub fn unhashed(camera: &Camera, settings: &RenderSettings) -> Self {
        Self::with_scene_hash(String::new(), camera, settings)
    }

    /// Whether the scene's hash is in it (not [`Self::unhashed`]).
    pub fn is_hashed(&self) -> bool {
        !self.scene.is_empty()
    }

    /// The fingerprint of rendering `scene` as `camera` sees it with `settings`.
    pub fn new(scene: &PreparedScene, camera: &Camera, settings: &RenderSettings) -> Self {
        let (geometry, textures, shading) = (&scene.geometry, &scene.textures, &scene.shading);
        let counts = [shading.object_count, shading.light_count];
        let map_placement = shading.environment_map.map_or([0; 4], |m| {
            [m.width, m.height, m.scale.to_bits(), m.rotation.to_bits()]
        });
        let scene_hash = sha256_hex(&[
            bytemuck::cast_slice(&geometry.nodes),
            bytemuck::cast_slice(&geometry.primitives),
            bytemuck::cast_slice(&geometry.vertices),
            bytemuck::cast_slice(&geometry.triangles),
            bytemuck::cast_slice(&geometry.shapes),
            bytemuck::cast_slice(&geometry.instances),
            bytemuck::cast_slice(&textures.texels),
            bytemuck::cast_slice(&shading.objects),
            bytemuck::cast_slice(&shading.materials),
            bytemuck::cast_slice(&shading.param_blocks),
            bytemuck::cast_slice(&shading.texture_slots),
            bytemuck::cast_slice(&shading.lights),
            bytemuck::cast_slice(&counts),
            bytemuck::cast_slice(&shading.environment.to_array()),
            bytemuck::cast_slice(&scene.environment.texels),
            bytemuck::cast_slice(&scene.environment.distribution),
            bytemuck::cast_slice(&map_placement),
        ]);
        Self::with_scene_hash(scene_hash, camera, settings)
    }

    /// The fingerprint with the scene's hash `scene_hash`.
    fn with_scene_hash(scene_hash: String, camera: &Camera, settings: &RenderSettings) -> Self {
        let gpu_camera = GpuCamera::new(camera);
        Self {
            scene: scene_hash,
            camera: sha256_hex(&[bytemuck::bytes_of(&gpu_camera)]),
            width: camera.width,
            height: camera.height,
            seed: settings.seed,
            sampler: match settings.sampler {
                Sampler::Sobol => "sobol",
                Sampler::Independent => "independent",
            }
            .into(),
            max_depth: settings.max_depth,
            rr_depth: settings.rr_depth,
            aovs: if settings.aovs {
                AOV_NAMES.map(String::from).to_vec()
            } else {
                Vec::new()
            },
        }
    }

    /// Whether the render accumulates the auxiliary images.
    pub fn has_aovs(&self) -> bool {
        !self.aovs.is_empty()
    }

    /// What differs between `self` and `other`, called `names.0` and `names.1`, one phrase
    /// each.
    pub fn differences(&self, other: &Self, names: (&str, &str)) -> Vec<String> {
        let mut out = Vec::new();
        let mut differ = |what: &str, a: String, b: String| {
            if a != b {
                out.push(format!("{what} {a} in {}, {b} in {}", names.0, names.1));
            }
        };
        let size = |f: &Self| format!("{}x{}", f.width, f.height);
        differ("image size", size(self), size(other));
        differ("seed", self.seed.to_string(), other.seed.to_string());
        differ("sampler", self.sampler.clone(), other.sampler.clone());
        differ(
            "max_depth",
            self.max_depth.to_string(),
            other.max_depth.to_string(),
        );
        differ(
            "rr_depth",
            self.rr_depth.to_string(),
            other.rr_depth.to_string(),
        );
        let aovs = |f: &Self| match f.aovs.is_empty() {
            true => "none".to_owned(),
            false => f.aovs.join(","),
        };
        differ("auxiliary images", aovs(self), aovs(other));
        if self.camera != other.camera {
            out.push("the camera differs".into());
        }
        if self.scene != other.scene {
            out.push(
                "the scene differs (its shapes, meshes, textures, materials or lights)".into(),
            );
        }
        out
    }
}

/// A state file that cannot be used, and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StateError {
    /// Not a state file, or one of another version.
    #[error("not a pathlight state file ({0})")]
    Foreign(String),
    /// Cut short or changed since it was written.
    #[error("corrupt: {0}")]
    Corrupt(String),
    /// It does not fit what it is used with (another scene, overlapping samples, ...).
    #[error("{0}")]
    Mismatch(String),
}

/// The JSON header.
#[derive(Debug, Serialize, Deserialize)]
struct Header {
    fingerprint: Fingerprint,
    /// The sample range the render was asked for.
    target: [u32; 2],
    /// Where it was rendered (informational: backends merge).
    backend: String,
}

/// A render's state: its sums, the samples every row holds, what was rendered and which
/// samples were asked for.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderState {
    /// What was rendered.
    pub fingerprint: Fingerprint,
    /// The sample indices the render was asked for.
    pub target: Range<u32>,
    /// Where it was rendered.
    pub backend: String,
    /// Per row, the sample indices every pixel of the row holds.
    pub rows: Vec<Range<u32>>,
    /// The fixed-point sums, row by row.
    pub sums: Vec<GpuAccumPixel>,
    /// The auxiliary images' sums, row by row (empty when the fingerprint has none).
    pub aovs: Vec<GpuAovPixel>,
}

impl RenderState {
    /// The state of a render of `target` whose accumulation is `accumulation`.
    pub fn new(
        fingerprint: Fingerprint,
        target: Range<u32>,
        backend: String,
        accumulation: Accumulation,
    ) -> Self {
        let cursor = accumulation.cursor;
        let first = cursor.first_sample;
        let rows = (0..fingerprint.height)
            .map(|y| first..first + cursor.row_samples(y))
            .collect();
        Self {
            fingerprint,
            target,
            backend,
            rows,
            sums: accumulation.sums,
            aovs: accumulation.aovs,
        }
    }

    /// Samples of the target no row holds yet (what a resumed render would add), counted
    /// per pixel of the row with the fewest.
    pub fn remaining(&self) -> u32 {
        let done = self.rows.iter().map(|r| r.end).min().unwrap_or(0);
        self.target.end.saturating_sub(done)
    }

    /// The accumulation a renderer resumes from. Refused where the rows are not what one
    /// render leaves (a merge with gaps): every row from the same first sample, rows
    /// `0 .. k` one sample ahead of the others.
    pub fn accumulation(&self) -> Result<Accumulation, StateError> {
        let first = self.rows.first().map_or(self.target.start, |r| r.start);
        let last = self.rows.last().map_or(first, |r| r.end);
        // In u64: a file may hold any u32 range, `u32::MAX` included.
        let end_of = |y: usize, ahead: usize| u64::from(last) + u64::from(y < ahead);
        let ahead = self
            .rows
            .iter()
            .take_while(|r| u64::from(r.end) == end_of(0, 1))
            .count();
        let fits = self
            .rows
            .iter()
            .enumerate()
            .all(|(y, r)| r.start == first && u64::from(r.end) == end_of(y, ahead));
        if !fits || (ahead > 0 && ahead == self.rows.len()) {
            return Err(StateError::Mismatch(
                "its rows hold samples no single render leaves (a merge with gaps?); only \
                 the image can be made from it"
                    .into(),
            ));
        }
        Ok(Accumulation {
            cursor: SampleCursor {
                first_sample: first,
                samples: last - first,
                rows_ahead: ahead as u32,
            },
            sums: self.sums.clone(),
            aovs: self.aovs.clone(),
        })
    }

    /// The image: each pixel the mean of the samples its row holds.
    pub fn film(&self) -> Film {
        Film::from_row_sums(self.fingerprint.width, &self.counts(), &self.sums)
    }

    /// The auxiliary images (albedo, normal) of the same samples, if it has them.
    pub fn aov_films(&self) -> Option<(Film, Film)> {
        Film::aovs_from_row_sums(self.fingerprint.width, &self.counts(), &self.aovs)
    }

    /// Per row, the samples each of its pixels holds.
    fn counts(&self) -> Vec<u32> {
        self.rows.iter().map(|r| r.len() as u32).collect()
    }

    /// The file's bytes (see the module documentation).
    pub fn encode(&self) -> Vec<u8> {
        let header = Header {
            fingerprint: self.fingerprint.clone(),
            target: [self.target.start, self.target.end],
            backend: self.backend.clone(),
        };
        let json = serde_json::to_vec(&header).expect("the header serialises");
        let mut bytes = Vec::with_capacity(
            PREAMBLE
                + json.len()
                + self.rows.len() * 8
                + self.sums.len() * 32
                + self.aovs.len() * 64
                + CHECKSUM,
        );
        bytes.extend_from_slice(MAGIC);
        bytes.extend_from_slice(&VERSION.to_le_bytes());
        bytes.extend_from_slice(&(json.len() as u32).to_le_bytes());
        bytes.extend_from_slice(&json);
        for row in &self.rows {
            bytes.extend_from_slice(&row.start.to_le_bytes());
            bytes.extend_from_slice(&row.end.to_le_bytes());
        }
        let aov_sums = self.aovs.iter().flat_map(|a| [&a.albedo, &a.normal]);
        for sum in self.sums.iter().chain(aov_sums) {
            for word in sum.hi.iter().chain(&sum.lo) {
                bytes.extend_from_slice(&word.to_le_bytes());
            }
        }
        let checksum = Sha256::digest(&bytes);
        bytes.extend_from_slice(&checksum);
        bytes
    }

    /// Reads a state from the bytes of a file; refuses foreign, corrupt or inconsistent ones.
    pub fn decode(bytes: &[u8]) -> Result<Self, StateError> {
        if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
            return Err(StateError::Foreign(
                "it does not start with the magic bytes".into(),
            ));
        }
        if bytes.len() < PREAMBLE + CHECKSUM {
            return Err(StateError::Corrupt(format!("only {} bytes", bytes.len())));
        }
        let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
        let version = word(16);
        if version != VERSION {
            let why = if version == 1 {
                " (written before states held auxiliary images): render it again"
            } else {
                ""
            };
            return Err(StateError::Foreign(format!(
                "format version {version}; this pathlight reads version {VERSION}{why}"
            )));
        }
        let (body, checksum) = bytes.split_at(bytes.len() - CHECKSUM);
        if Sha256::digest(body).as_slice() != checksum {
            return Err(StateError::Corrupt(
                "the checksum does not match: the file was cut short or changed".into(),
            ));
        }
        let header_len = word(20) as usize;
        let header_end = PREAMBLE
            .checked_add(header_len)
            .filter(|&end| end <= body.len())
            .ok_or_else(|| StateError::Corrupt(format!("a header of {header_len} bytes")))?;
        let header: Header = serde_json::from_slice(&body[PREAMBLE..header_end])
            .map_err(|err| StateError::Corrupt(format!("the header: {err}")))?;
        let (width, height) = (header.fingerprint.width, header.fingerprint.height);
        check_resolution(width, height)
            .map_err(|err| StateError::Corrupt(format!("the header: {err}")))?;
        let aovs = &header.fingerprint.aovs;
        if !aovs.is_empty() && *aovs != AOV_NAMES {
            return Err(StateError::Corrupt(format!(
                "the header names auxiliary images {aovs:?}; a state holds {AOV_NAMES:?} or none"
            )));
        }
        let pixels = width as usize * height as usize;
        let rows_len = height as usize * 8;
        let sums_len = pixels * 32;
        let aovs_len = if aovs.is_empty() { 0 } else { pixels * 64 };
        if body.len() - header_end != rows_len + sums_len + aovs_len {
            return Err(StateError::Corrupt(format!(
                "{} bytes of rows and sums where {width}x{height} needs {}",
                body.len() - header_end,
                rows_len + sums_len + aovs_len
            )));
        }
        let target = header.target[0]..header.target[1];
        let words = |from: usize, count: usize| (0..count).map(move |i| word(from + 4 * i));
        let row_words: Vec<u32> = words(header_end, height as usize * 2).collect();
        let rows: Vec<Range<u32>> = row_words.chunks(2).map(|w| w[0]..w[1]).collect();
        if target.start > target.end || rows.iter().any(|r| r.start > r.end) {
            return Err(StateError::Corrupt(
                "a sample range ends before it starts".into(),
            ));
        }
        let sum_words: Vec<u32> = words(header_end + rows_len, (sums_len + aovs_len) / 4).collect();
        let mut all = sum_words.chunks(8).map(|w| GpuAccumPixel {
            hi: [w[0], w[1], w[2], w[3]],
            lo: [w[4], w[5], w[6], w[7]],
        });
        let sums = all.by_ref().take(pixels).collect();
        let aov_sums: Vec<GpuAccumPixel> = all.collect();
        let aovs = aov_sums
            .chunks(2)
            .map(|p| GpuAovPixel {
                albedo: p[0],
                normal: p[1],
            })
            .collect();
        Ok(Self {
            fingerprint: header.fingerprint,
            target,
            backend: header.backend,
            rows,
            sums,
            aovs,
        })
    }
}

/// Parts summed by [`merge`].
#[derive(Debug, Clone, PartialEq)]
pub struct Merged {
    /// The sums of every part; per row, the range from its first sample to its last (a row
    /// with a gap holds fewer: see `counts` and `missing`).
    pub state: RenderState,
    /// Per row, the samples each pixel holds (with gaps, fewer than its range).
    pub counts: Vec<u32>,
    /// Sample ranges of the parts' targets no part holds, as `(rows, samples)`, rows
    /// with the same gaps grouped.
    pub missing: Vec<(Range<u32>, Range<u32>)>,
}

impl Merged {
    /// The image: each pixel the mean of the samples every part holds for it.
    pub fn film(&self) -> Film {
        Film::from_row_sums(self.state.fingerprint.width, &self.counts, &self.state.sums)
    }

    /// The auxiliary images (albedo, normal) of the same samples, if the parts have them.
    pub fn aov_films(&self) -> Option<(Film, Film)> {
        Film::aovs_from_row_sums(self.state.fingerprint.width, &self.counts, &self.state.aovs)
    }

    /// The merged state, refused where a row's samples have a gap (a state holds one range
    /// per row). Samples missing after a row's last one are no gap: a render resumes there.
    pub fn into_state(self) -> Result<RenderState, StateError> {
        let gapped = self
            .state
            .rows
            .iter()
            .zip(&self.counts)
            .position(|(range, &count)| range.len() as u32 != count);
        match gapped {
            Some(y) => Err(StateError::Mismatch(format!(
                "row {y} has a gap in its samples: only an image can be made of these parts"
            ))),
            None => Ok(self.state),
        }
    }
}

/// Sums `parts` (each named for messages) exactly: they must have been rendered from the same
/// scene and settings, and no two may hold the same sample of a row.
pub fn merge(parts: &[(String, RenderState)]) -> Result<Merged, StateError> {
    let Some((first_name, first)) = parts.first() else {
        return Err(StateError::Mismatch("nothing to merge".into()));
    };
    for (name, part) in &parts[1..] {
        let differences = first
            .fingerprint
            .differences(&part.fingerprint, (first_name, name));
        if !differences.is_empty() {
            return Err(StateError::Mismatch(format!(
                "{name} is not of the render {first_name} is: {}",
                differences.join("; ")
            )));
        }
    }
    let height = first.fingerprint.height as usize;
    let target = parts.iter().map(|(_, p)| p.target.start).min().unwrap_or(0)
        ..parts.iter().map(|(_, p)| p.target.end).max().unwrap_or(0);
    let mut sums = vec![GpuAccumPixel::default(); first.sums.len()];
    let mut aovs = vec![GpuAovPixel::default(); first.aovs.len()];
    for (_, part) in parts {
        for (sum, add) in sums.iter_mut().zip(&part.sums) {
            sum.accumulate(add);
        }
        for (sum, add) in aovs.iter_mut().zip(&part.aovs) {
            sum.accumulate(add);
        }
    }
    let mut rows = Vec::with_capacity(height);
    let mut counts = Vec::with_capacity(height);
    let mut gaps_per_row = Vec::with_capacity(height);
    for y in 0..height {
        let mut ranges: Vec<(&Range<u32>, &str)> = parts
            .iter()
            .map(|(name, p)| (&p.rows[y], name.as_str()))
            .filter(|(r, _)| !r.is_empty())
            .collect();
        ranges.sort_by_key(|(r, _)| r.start);
        for pair in ranges.windows(2) {
            let ((a, a_name), (b, b_name)) = (pair[0], pair[1]);
            if b.start < a.end {
                return Err(StateError::Mismatch(format!(
                    "{a_name} and {b_name} both hold samples {}..{} of row {y}",
                    b.start,
                    a.end.min(b.end)
                )));
            }
        }
        let mut gaps = Vec::new();
        let mut at = target.start;
        for (range, _) in &ranges {
            if range.start > at {
                gaps.push(at..range.start);
            }
            at = at.max(range.end);
        }
        if at < target.end {
            gaps.push(at..target.end);
        }
        counts.push(ranges.iter().map(|(r, _)| r.len() as u32).sum());
        rows.push(match (ranges.first(), ranges.last()) {
            (Some((first, _)), Some((last, _))) => first.start..last.end,
            _ => target.start..target.start,
        });
        gaps_per_row.push(gaps);
    }
    let mut missing: Vec<(Range<u32>, Range<u32>)> = Vec::new();
    for (y, gaps) in gaps_per_row.iter().enumerate() {
        for gap in gaps {
            let y = y as u32;
            match missing
                .iter_mut()
                .find(|(rows, g)| rows.end == y && g == gap)
            {
                Some((rows, _)) => rows.end = y + 1,
                None => missing.push((y..y + 1, gap.clone())),
            }
        }
    }
    Ok(Merged {
        state: RenderState {
            fingerprint: first.fingerprint.clone(),
            target,
            backend: first.backend.clone(),
            rows,
            sums,
            aovs,
        },
        counts,
        missing,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fingerprint(width: u32, height: u32) -> Fingerprint {
        Fingerprint {
            scene: "s".into(),
            camera: "c".into(),
            width,
            height,
            seed: 1,
            sampler: "sobol".into(),
            max_depth: 8,
            rr_depth: 4,
            aovs: Vec::new(),
        }
    }

    /// A 3x2 state of samples `first..first + samples` (row 0 one more when `ahead`), each
    /// sample worth 1.25 in every channel.
    fn state(first: u32, samples: u32, ahead: bool, target: Range<u32>) -> RenderState {
        let rows_ahead = u32::from(ahead);
        let sums = (0..6)
            .map(|i| {
                let n = f64::from(samples + u32::from(i < 3 && ahead)) * 1.25;
                let (hi, lo) = (n as u32, (n.fract() * 4_294_967_296.0) as u32);
                GpuAccumPixel {
                    hi: [hi, hi, hi, 0],
                    lo: [lo, lo, lo, 0],
                }
            })
            .collect();
        let accumulation = Accumulation {
            cursor: SampleCursor {
                first_sample: first,
                samples,
                rows_ahead,
            },
            sums,
            aovs: Vec::new(),
        };
        RenderState::new(fingerprint(3, 2), target, "test".into(), accumulation)
    }

    #[test]
    fn a_state_survives_its_file_and_any_changed_byte_is_refused() {
        let original = state(4, 3, true, 0..16);
        let bytes = original.encode();
        assert_eq!(RenderState::decode(&bytes).unwrap(), original);
        assert_eq!(original.remaining(), 9);
        // Every byte: magic, version, header length, header, rows, sums, checksum.
        for at in 0..bytes.len() {
            let mut changed = bytes.clone();
            changed[at] ^= 0x10;
            let err = RenderState::decode(&changed).expect_err("a changed byte");
            match at {
                0..16 => assert!(matches!(err, StateError::Foreign(_)), "{at}: {err}"),
                16..20 => assert!(matches!(err, StateError::Foreign(_)), "{at}: {err}"),
                _ => assert!(matches!(err, StateError::Corrupt(_)), "{at}: {err}"),
            }
        }
        for len in [0, 10, 30, bytes.len() / 2, bytes.len() - 1] {
            assert!(RenderState::decode(&bytes[..len]).is_err(), "cut at {len}");
        }
    }

    /// Files with a valid checksum but absurd contents (as a hand-made or foreign tool's
    /// file could have) are refused without a panic or an overflow.
    #[test]
    fn absurd_but_well_formed_states_are_refused() {
        for (width, height) in [(0, 2), (3, 0), (100_000, 2)] {
            let mut absurd = state(0, 1, false, 0..1);
            absurd.fingerprint.width = width;
            absurd.fingerprint.height = height;
            let err = RenderState::decode(&absurd.encode()).unwrap_err();
            assert!(
                err.to_string().contains("resolution"),
                "{width}x{height}: {err}"
            );
        }
        // Samples up to the last index: the state reads, but nothing resumes past it.
        let mut last = state(0, 1, false, 0..u32::MAX);
        last.rows = vec![u32::MAX - 1..u32::MAX, u32::MAX - 1..u32::MAX];
        let read = RenderState::decode(&last.encode()).unwrap();
        let accumulation = read.accumulation().unwrap();
        assert!(accumulation.check_fits(3, 2, false).is_err());
        last.rows = vec![u32::MAX - 1..u32::MAX, u32::MAX - 2..u32::MAX - 1];
        assert!(
            last.accumulation().is_err(),
            "rows from different first samples"
        );
    }

    #[test]
    fn a_state_gives_back_the_accumulation_it_was_made_of() {
        let original = state(4, 3, true, 0..16);
        let accumulation = original.accumulation().unwrap();
        assert_eq!(
            (
                accumulation.cursor.first_sample,
                accumulation.cursor.samples,
                accumulation.cursor.rows_ahead
            ),
            (4, 3, 1)
        );
        let film = original.film();
        assert_eq!(film.pixel(0, 0), [1.25; 3], "4 samples of 1.25");
        assert_eq!(film.pixel(2, 1), [1.25; 3], "3 samples of 1.25");
    }

    #[test]
    fn merges_add_exactly_and_report_overlaps_and_gaps() {
        let named = |parts: Vec<RenderState>| -> Vec<(String, RenderState)> {
            parts
                .into_iter()
                .enumerate()
                .map(|(i, p)| (format!("part{i}"), p))
                .collect()
        };
        // 0..5 and 5..9 (row 0 of the second one sample ahead) join up.
        let merged = merge(&named(vec![
            state(0, 5, false, 0..5),
            state(5, 4, true, 5..10),
        ]))
        .unwrap();
        assert_eq!(merged.state.rows, [0..10, 0..9]);
        assert_eq!(merged.missing, [(1..2, 9..10)], "row 1 lacks sample 9");
        assert_eq!(merged.film().pixel(0, 0), [1.25; 3]);
        let accumulation = merged.into_state().unwrap().accumulation().unwrap();
        assert_eq!(
            (accumulation.cursor.samples, accumulation.cursor.rows_ahead),
            (9, 1)
        );

        // Overlap.
        let err = merge(&named(vec![
            state(0, 5, false, 0..5),
            state(3, 4, false, 3..7),
        ]))
        .unwrap_err();
        assert_eq!(
            err.to_string(),
            "part0 and part1 both hold samples 3..5 of row 0"
        );
        // A gap in the middle: the image still comes out, the accumulation does not.
        let merged = merge(&named(vec![
            state(0, 2, false, 0..2),
            state(4, 2, false, 4..6),
        ]))
        .unwrap();
        assert_eq!(merged.missing, [(0..2, 2..4)]);
        assert_eq!(merged.counts, [4, 4]);
        assert!(merged.into_state().is_err());
        // Another render.
        let mut other = state(2, 2, false, 2..4);
        other.fingerprint.seed = 2;
        let err = merge(&named(vec![state(0, 2, false, 0..2), other])).unwrap_err();
        assert!(
            err.to_string().contains("seed 1 in part0, 2 in part1"),
            "{err}"
        );
    }
}
