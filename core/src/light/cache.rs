//! The precomputation on disk. A model's gathers (sky coefficients, form
//! factors, sensor rays) are stored under a key hashed from what they
//! depend on ([`key`]: the loaded geometry and patches, the materials' light
//! passing, the sensors' placement, the settings and this format's version;
//! not comments or names), with the shadow tracer's BVH (building it was
//! most of a warm start on a large model). A file whose header, length or checksum does not
//! match is rebuilt, never trusted. Files are written whole and renamed into
//! place (a reader never sees half a file), and the folder is kept under a
//! size bound ([`size_limit`]), least recently used files first to go;
//! temporary files of processes that died mid-write are removed.

use std::fs;
use std::io::{self, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, SystemTime};

use glam::DVec3;

use super::bvh::Tracer;
use super::gather::{Gather, SensorGeometry};
use super::landings::{Landings, RunPoints};
use super::{LightModel, LightSettings};
use crate::scene::{MaterialKind, Scene};
use crate::sky::SkyPatches;

const MAGIC: &[u8; 8] = b"HELIOLT\0";
/// Bump when the model or its layout changes.
const FORMAT: u32 = 23;

/// What happened to the cache.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CacheOutcome {
    /// Loaded from disk.
    Hit(PathBuf),
    /// Computed and stored.
    Stored(PathBuf),
    /// A file was there but unusable (why); recomputed and replaced.
    Rebuilt(PathBuf, String),
    /// Computed; not stored (why: disabled, or the folder is not writable).
    Skipped(String),
}

/// The default cache folder: `$HELIODON_CACHE_DIR`, else
/// `$XDG_CACHE_HOME/heliodon`, else `~/.cache/heliodon`.
pub fn default_dir() -> Option<PathBuf> {
    if let Some(dir) = std::env::var_os("HELIODON_CACHE_DIR") {
        return Some(PathBuf::from(dir));
    }
    if let Some(dir) = std::env::var_os("XDG_CACHE_HOME") {
        return Some(PathBuf::from(dir).join("heliodon"));
    }
    std::env::var_os("HOME").map(|home| PathBuf::from(home).join(".cache/heliodon"))
}

/// A 64-bit hash of a stream of bytes, taken eight at a time (FxHash's
/// step: rotate, xor, multiply by an odd constant), ended by the length:
/// stable across platforms and Rust versions, as the keys and checksums of
/// cache files must be. A warm start checks tens of megabytes; FNV's byte
/// a step took 50 ms of the furnished floor's 0.25 s.
pub(crate) struct StableHash {
    state: u64,
    /// Bytes not yet making a whole word, and how many.
    pending: [u8; 8],
    filled: usize,
    len: u64,
}

impl StableHash {
    pub fn new() -> Self {
        Self { state: 0, pending: [0; 8], filled: 0, len: 0 }
    }

    fn word(&mut self, word: u64) {
        self.state = (self.state.rotate_left(5) ^ word).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }

    pub fn bytes(&mut self, mut data: &[u8]) -> &mut Self {
        self.len += data.len() as u64;
        if self.filled > 0 {
            let take = data.len().min(8 - self.filled);
            self.pending[self.filled..self.filled + take].copy_from_slice(&data[..take]);
            (self.filled, data) = (self.filled + take, &data[take..]);
            if self.filled < 8 {
                return self;
            }
            self.word(u64::from_le_bytes(self.pending));
            self.filled = 0;
        }
        let words = data.chunks_exact(8);
        let rest = words.remainder();
        for word in words {
            self.word(u64::from_le_bytes(word.try_into().expect("eight bytes")));
        }
        self.pending[..rest.len()].copy_from_slice(rest);
        self.filled = rest.len();
        self
    }

    pub fn u64(&mut self, v: u64) -> &mut Self {
        self.bytes(&v.to_le_bytes())
    }

    pub fn f64(&mut self, v: f64) -> &mut Self {
        self.u64(v.to_bits())
    }

    /// `v`'s four bytes: two make a word without the byte-by-byte path.
    pub fn u32(&mut self, v: u32) -> &mut Self {
        match self.filled {
            0 => {
                self.pending[..4].copy_from_slice(&v.to_le_bytes());
                (self.filled, self.len) = (4, self.len + 4);
            }
            4 => {
                self.len += 4;
                self.filled = 0;
                let low = u64::from(u32::from_le_bytes(self.pending[..4].try_into().expect("four bytes")));
                self.word(low | u64::from(v) << 32);
            }
            _ => {
                self.bytes(&v.to_le_bytes());
            }
        }
        self
    }

    /// `values`, each by its bits.
    pub fn f32s(&mut self, values: &[f32]) -> &mut Self {
        for v in values {
            self.u32(v.to_bits());
        }
        self
    }

    /// Points, each coordinate by its bits.
    pub fn points(&mut self, points: &[glam::Vec3]) -> &mut Self {
        for p in points {
            self.f32s(&p.to_array());
        }
        self
    }

    /// `items` in blocks of `per_block` hashed side by side, each item
    /// with `each`, then the count and the blocks' hashes in order: the
    /// same on any number of threads (a large model's triangles were 45 ms
    /// of every start in one stream).
    pub fn blocks_of<T: Sync>(&mut self, items: &[T], per_block: usize, each: impl Fn(&mut Self, &T) + Sync) -> &mut Self {
        let blocks = crate::parallel::par_chunks(None, items, per_block, |block| {
            let mut hash = Self::new();
            block.iter().for_each(|item| each(&mut hash, item));
            hash.finish()
        });
        self.u64(items.len() as u64);
        for block in blocks {
            self.u64(block);
        }
        self
    }

    /// The hash of everything written so far.
    pub fn finish(&self) -> u64 {
        let mut end = Self { state: self.state, ..Self::new() };
        let mut tail = [0; 8];
        tail[..self.filled].copy_from_slice(&self.pending[..self.filled]);
        end.word(u64::from_le_bytes(tail));
        end.word(self.len);
        end.state
    }
}

/// The key of a scene's precomputation: what the gathers depend on, and
/// nothing else. The patches' geometry (the model after loading, its frame
/// and patch sizes), which materials pass light and how, which surface has
/// which, the sensors' placement, and the settings that shape the result;
/// not comments, names, reflectances, the site or the thread count. And
/// the code that computes them: the core's sources (`build.rs`'s hash, as
/// the scene cache has it), so a build that gathers otherwise never reads
/// what an older one stored, whether or not [`FORMAT`] was bumped (once it
/// was not, and a changed gather read the last one's light).
///
/// The sides left dark inside solids follow from what is hashed here (the
/// model's triangles with their file's vertices, its surfaces and
/// clusters, which materials pass light), so a warm start need not find
/// them.
pub fn key(scene: &Scene, settings: &LightSettings) -> u64 {
    let mut hash = StableHash::new();
    hash.bytes(MAGIC).u64(u64::from(FORMAT)).bytes(env!("CARGO_PKG_VERSION").as_bytes());
    hash.bytes(env!("HELIODON_CORE_SOURCE_HASH").as_bytes());
    hash.blocks_of(&scene.patches.triangles, 1 << 14, |h, triangle| {
        h.points(triangle);
    });
    // How many rays each patch traces follows the focus.
    hash.f32s(&scene.patch_sizing.as_floats());
    for sensor in &scene.sensors {
        hash.f32s(&[sensor.position.to_array(), sensor.normal.to_array(), sensor.axes[0].to_array(), sensor.axes[1].to_array()].concat());
        hash.f32s(&[sensor.size.unwrap_or(-1.0)]);
    }
    // Which shells close (the sides dark inside solids) depends on the
    // model's triangles and on its file's vertices.
    hash.blocks_of(&scene.triangles, 1 << 14, |h, triangle| {
        h.points(&triangle.vertices);
        for vertex in triangle.file_vertices {
            h.u64(u64::from(vertex));
        }
    });
    for patch in &scene.patches.patches {
        hash.u64(u64::from(patch.triangles.end)).u64(u64::from(patch.surface)).u64(u64::from(patch.material));
    }
    for (patch, surfaces) in &scene.patches.clusters {
        hash.u64(u64::from(*patch));
        for &surface in surfaces {
            hash.u64(u64::from(surface));
        }
    }
    // Materials edited at run time: what the gathers depend on (which
    // materials pass light, and glass transmittance; not reflectances), and
    // which surfaces have which.
    for material in &scene.materials {
        match &material.kind {
            MaterialKind::Diffuse { .. } => hash.u64(0),
            MaterialKind::Glass { transmittance } => hash.u64(1).u64(u64::from(transmittance.to_bits())),
            MaterialKind::Panel { .. } => hash.u64(2),
        };
    }
    // Surfaces given materials of their own at run time.
    for surface in &scene.surfaces {
        hash.u64(u64::from(surface.material)).u64(u64::from(surface.triangles.end));
    }
    hash.u64(settings.rays_per_patch as u64)
        .u64(settings.window_rays_per_patch as u64)
        .u64(settings.rays_per_sensor as u64)
        .u64(settings.sky_rays_per_sensor as u64)
        .u64(settings.window_rays_per_sensor as u64)
        .u64(settings.unseen_ray_share.to_bits())
        .u64(settings.sun_samples_per_patch as u64)
        .u64(settings.area_sensor_sun_grid as u64)
        .u64(u64::from(settings.sky_subdivision))
        .u64(settings.max_iterations as u64)
        .u64(settings.tolerance.to_bits());
    // The default sample keeps the keys it had before seeds were settings.
    if settings.seed != 0 {
        hash.u64(settings.seed);
    }
    hash.finish()
}

/// Precomputes `scene`, going through the cache in `dir` (none: no cache).
pub fn precompute_cached(
    scene: Arc<Scene>,
    settings: LightSettings,
    dir: Option<&Path>,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<(LightModel, CacheOutcome), String> {
    precompute_cached_beside(scene, settings, None, dir, progress)
}

/// [`precompute_cached`] beside a model of the same scene (the viewer's
/// model for display beside the settings' own): what the two have alike
/// (the tracers, the patch sides whose rays are the same, the sensors) is
/// `beside`'s, shared, not traced or held twice, whether the new model is
/// traced or read from the cache. The furnished floor of offices (17,273
/// of its 57,846 patch sides keep their rays for display): a cold view's
/// peak 1.94 → 1.80 GB and 43 → 37 s, a warm one's 1.90 → 1.81 GB.
pub fn precompute_cached_beside(
    scene: Arc<Scene>,
    settings: LightSettings,
    beside: Option<&LightModel>,
    dir: Option<&Path>,
    progress: &(dyn Fn(f64) + Sync),
) -> Result<(LightModel, CacheOutcome), String> {
    settings.check()?;
    let Some(dir) = dir else {
        // No file to name: the key is not worked out unless asked for.
        return Ok((LightModel::traced(scene, settings, beside, progress)?, CacheOutcome::Skipped("disabled".into())));
    };
    let key = key(&scene, &settings);
    let (model, outcome) = through_cache(
        Some(dir),
        &file_name(key),
        key,
        |blocks| LightModel::read_cached(&scene, settings, beside, blocks),
        || LightModel::traced(scene.clone(), settings, beside, progress),
        LightModel::save,
    )?;
    model.cache_key.get_or_init(|| key);
    Ok((model, outcome))
}

/// The name of the cache file of the precomputation keyed `key`.
fn file_name(key: u64) -> String {
    format!("{key:016x}")
}

/// Where the cache file `name` lives in `dir`.
fn file_path(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!("light-{name}.bin"))
}

/// One file of the cache (`light-{name}.bin` in `dir`) stored under `key`:
/// loaded when it is whole and `load` accepts its blocks (all of them),
/// else made by `compute` and stored as `save` writes it, block by block
/// (none: no cache, computed each time). Neither way is the file whole in
/// memory: Revit's Office_A (121,077 patches, 10,244 sensors) has a 240 MB
/// light file, which held beside the model it holds took `sensors`' warm
/// peak to 954 MB and its cold one to 1.04 GB (now 811 and 858 MB).
pub fn through_cache<T>(
    dir: Option<&Path>,
    name: &str,
    key: u64,
    load: impl FnOnce(&mut Blocks) -> Option<T>,
    compute: impl FnOnce() -> Result<T, String>,
    save: impl FnOnce(&T, &mut BlockWriter) -> io::Result<()>,
) -> Result<(T, CacheOutcome), String> {
    let Some(dir) = dir else {
        return Ok((compute()?, CacheOutcome::Skipped("disabled".into())));
    };
    let (path, found) = open_streamed_entry(dir, name, key);
    let rebuilt = match found {
        None => None,
        Some(Ok(file)) => {
            let mut blocks = Blocks { file, offset: 0 };
            match load(&mut blocks) {
                Some(value) if blocks.offset == blocks.file.len() => {
                    mark_used(&path);
                    return Ok((value, CacheOutcome::Hit(path)));
                }
                _ => Some(DOES_NOT_FIT.to_string()),
            }
        }
        Some(Err(why)) => Some(why),
    };
    let value = compute()?;
    let stored = StreamedWriter::create(&path, key).and_then(|mut out| {
        save(&value, &mut BlockWriter(&mut out))?;
        out.finish().map(drop)
    });
    Ok((value, stored_outcome(dir, path, stored, rebuilt)))
}

/// A cache file's payload written as blocks, each its length and its bytes.
pub struct BlockWriter<'a>(&'a mut StreamedWriter);

impl BlockWriter<'_> {
    /// Appends a block of what `write` writes.
    pub(crate) fn block(&mut self, write: impl FnOnce(&mut Writer)) -> io::Result<()> {
        let mut w = Writer::default();
        write(&mut w);
        self.bytes(&w.0)
    }

    /// Appends a block of `bytes`.
    pub(crate) fn bytes(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.0.append(&(bytes.len() as u64).to_le_bytes())?;
        self.0.append(bytes)
    }

    /// Appends `items` in blocks of `per_block`, each as `write` writes it.
    pub(crate) fn items<T>(&mut self, items: &[T], per_block: usize, write: impl Fn(&mut Writer, &T)) -> io::Result<()> {
        items.chunks(per_block.max(1)).try_for_each(|chunk| self.block(|w| chunk.iter().for_each(|item| write(w, item))))
    }
}

/// A cache file's blocks ([`BlockWriter`]), read one at a time in order.
pub struct Blocks {
    file: StreamedReader,
    offset: u64,
}

impl Blocks {
    /// The next block; `None` past the last or where a length runs past the end.
    pub(crate) fn next(&mut self) -> Option<Vec<u8>> {
        let mut len = [0; 8];
        self.file.read_at(self.offset, &mut len).ok()?;
        let len = u64::from_le_bytes(len);
        if len > self.file.len() - self.offset - 8 {
            return None;
        }
        let mut block = vec![0; len as usize];
        self.file.read_at(self.offset + 8, &mut block).ok()?;
        self.offset += 8 + len;
        Some(block)
    }

    /// `count` items as [`BlockWriter::items`] wrote them (`read` taking
    /// one), each block read whole; `None` when they do not fit.
    pub(crate) fn items<T>(&mut self, count: usize, read: impl Fn(&mut Reader) -> Option<T>) -> Option<Vec<T>> {
        let mut items = Vec::with_capacity(count);
        while items.len() < count {
            let block = self.next()?;
            let mut r = Reader(&block);
            while !r.is_empty() {
                items.push(read(&mut r)?);
            }
        }
        (items.len() == count).then_some(items)
    }
}

/// The cache file `name` in `dir` (its path) and its payload: `None` when
/// there is none, `Some(Err(why))` when it is not whole or not stored under
/// `key`. A caller that uses the payload marks the file used
/// ([`mark_used`]); one that cannot makes it again ([`store_entry`]).
pub(crate) fn open_entry(dir: &Path, name: &str, key: u64) -> (PathBuf, Option<Result<Payload, String>>) {
    let path = file_path(dir, name);
    // Every start tidies: temporary files of processes killed mid-write go,
    // and the folder keeps to its bound.
    tidy(dir, &path, size_limit());
    let found = fs::read(&path).ok().map(|bytes| {
        decode(&bytes, key)?;
        Ok(Payload(bytes))
    });
    (path, found)
}

/// [`open_entry`] for a file read in place ([`StreamedReader`]).
fn open_streamed_entry(dir: &Path, name: &str, key: u64) -> (PathBuf, Option<Result<StreamedReader, String>>) {
    let path = file_path(dir, name);
    tidy(dir, &path, size_limit());
    let found = StreamedReader::open(&path, key);
    (path, found)
}

/// A cache file read whole and checked: it derefs to its payload.
pub(crate) struct Payload(Vec<u8>);

impl std::ops::Deref for Payload {
    type Target = [u8];

    fn deref(&self) -> &[u8] {
        &self.0[HEADER..]
    }
}

/// Stores `payload` under `key` at `path` (from [`open_entry`]): written
/// whole, then renamed into place. `rebuilt` says why a file there was
/// not used.
pub(crate) fn store_entry(dir: &Path, path: PathBuf, key: u64, payload: &[u8], rebuilt: Option<String>) -> CacheOutcome {
    let stored = fs::create_dir_all(dir).and_then(|_| {
        // Write then rename, so a reader never sees half a file.
        let partial = temporary_path(&path);
        write_file(&partial, payload, key)?;
        fs::rename(&partial, &path)
    });
    stored_outcome(dir, path, stored, rebuilt)
}

/// What storing the file at `path` came to (`rebuilt`: why a file there
/// was not used); the folder tidied to its bound once it is stored.
fn stored_outcome(dir: &Path, path: PathBuf, stored: io::Result<()>, rebuilt: Option<String>) -> CacheOutcome {
    if stored.is_ok() {
        tidy(dir, &path, size_limit());
    }
    match (stored, rebuilt) {
        (Err(e), _) => CacheOutcome::Skipped(format!("cannot write {}: {e}", path.display())),
        (Ok(()), Some(why)) => CacheOutcome::Rebuilt(path, why),
        (Ok(()), None) => CacheOutcome::Stored(path),
    }
}

/// [`through_cache`] for a file too big to hold in memory: loaded in place
/// ([`StreamedReader`]) when it is whole and `load` accepts it (else `load`
/// says why not), else written by `write` as it is made
/// ([`StreamedWriter`]) and loaded from what was written. `None` when it
/// can be neither loaded nor stored (the caller then does without the
/// file).
pub(crate) fn through_streamed_cache<T>(
    dir: &Path,
    name: &str,
    key: u64,
    load: impl Fn(StreamedReader) -> Result<T, String>,
    write: impl FnOnce(&mut StreamedWriter) -> io::Result<()>,
) -> Option<(T, CacheOutcome)> {
    let (path, found) = open_streamed_entry(dir, name, key);
    let rebuilt = match found {
        None => None,
        Some(Ok(file)) => match load(file) {
            Ok(value) => {
                mark_used(&path);
                return Some((value, CacheOutcome::Hit(path)));
            }
            Err(why) => Some(why),
        },
        Some(Err(why)) => Some(why),
    };
    let mut out = StreamedWriter::create(&path, key).ok()?;
    write(&mut out).ok()?;
    let value = load(out.finish().ok()?).ok()?;
    Some((value, stored_outcome(dir, path, Ok(()), rebuilt)))
}

/// Side gathers per block of a light file (a few MB on a large model).
const GATHERS_PER_BLOCK: usize = 4096;
/// Sensors per block of a light file.
const SENSORS_PER_BLOCK: usize = 256;

/// Why a whole file was not used: what it holds is for another scene.
pub(crate) const DOES_NOT_FIT: &str = "its contents do not fit the scene";

/// Used now: the last file to be evicted.
pub(crate) fn mark_used(path: &Path) {
    let _ = fs::File::options().append(true).open(path).and_then(|f| f.set_modified(SystemTime::now()));
}

/// Where a file is written before it is renamed into place.
fn temporary_path(path: &Path) -> PathBuf {
    path.with_extension(format!("tmp{}", std::process::id()))
}

/// A cache file too big to hold in memory, written as its payload comes:
/// into a temporary file, checksummed on the way, then renamed into place
/// whole ([`Self::finish`]). Dropped unfinished, the temporary file goes.
pub(crate) struct StreamedWriter {
    out: io::BufWriter<fs::File>,
    partial: PathBuf,
    path: PathBuf,
    key: u64,
    len: u64,
    checksum: StableHash,
}

impl StreamedWriter {
    /// Starts `path`'s file (its folder made if need be).
    pub fn create(path: &Path, key: u64) -> io::Result<Self> {
        if let Some(dir) = path.parent() {
            fs::create_dir_all(dir)?;
        }
        let partial = temporary_path(path);
        let file = fs::File::options().read(true).write(true).create(true).truncate(true).open(&partial)?;
        let mut out = io::BufWriter::new(file);
        out.write_all(&[0; HEADER])?;
        Ok(Self { out, partial, path: path.to_path_buf(), key, len: 0, checksum: StableHash::new() })
    }

    /// Appends to the payload.
    pub fn append(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.checksum.bytes(bytes);
        self.len += bytes.len() as u64;
        self.out.write_all(bytes)
    }

    /// Writes the header, puts the file in place and keeps it open for
    /// reading (what was written needs no second check).
    pub fn finish(mut self) -> io::Result<StreamedReader> {
        self.out.flush()?;
        let file = self.out.get_mut();
        file.seek(SeekFrom::Start(0))?;
        file.write_all(&header(self.key, self.len, self.checksum.finish()))?;
        fs::rename(&self.partial, &self.path)?;
        let file = self.out.get_ref().try_clone()?;
        Ok(StreamedReader { file: Mutex::new(file), len: self.len })
    }
}

impl Drop for StreamedWriter {
    fn drop(&mut self) {
        // Gone already when renamed into place.
        let _ = fs::remove_file(&self.partial);
    }
}

/// A cache file read piece by piece in place ([`Self::read_at`]), its
/// header and whole-payload checksum checked once when opened; the open
/// file stays the one checked even if another process replaces or evicts
/// the path meanwhile.
pub(crate) struct StreamedReader {
    file: Mutex<fs::File>,
    len: u64,
}

impl StreamedReader {
    /// `path`'s file when it is whole and stored under `key`; `None` when
    /// there is no file, `Some(Err(why))` when it cannot be trusted.
    pub fn open(path: &Path, key: u64) -> Option<Result<Self, String>> {
        let mut file = fs::File::open(path).ok()?;
        Some((|| {
            let mut head = Vec::with_capacity(HEADER);
            Read::by_ref(&mut file).take(HEADER as u64).read_to_end(&mut head).map_err(|e| format!("cannot read: {e}"))?;
            let (len, checksum) = read_header(&head, key)?;
            let mut hash = StableHash::new();
            let mut chunk = vec![0; 1 << 20];
            let mut read = 0u64;
            loop {
                let n = file.read(&mut chunk).map_err(|e| format!("cannot read: {e}"))?;
                if n == 0 {
                    break;
                }
                hash.bytes(&chunk[..n]);
                read += n as u64;
            }
            check_payload((len, checksum), read, hash.finish())?;
            Ok(Self { file: Mutex::new(file), len })
        })())
    }

    /// The payload's length in bytes.
    pub fn len(&self) -> u64 {
        self.len
    }

    /// Fills `buf` from the payload at `offset`.
    pub fn read_at(&self, offset: u64, buf: &mut [u8]) -> io::Result<()> {
        if offset + buf.len() as u64 > self.len {
            return Err(io::Error::new(io::ErrorKind::UnexpectedEof, "past the end of the payload"));
        }
        let mut file = self.file.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        file.seek(SeekFrom::Start(HEADER as u64 + offset))?;
        file.read_exact(buf)
    }
}

/// The cache folder's bound in bytes: `$HELIODON_CACHE_MAX_MB` (MiB), else
/// 2 GiB. Past it, the least recently used files go.
pub fn size_limit() -> u64 {
    const DEFAULT_MIB: u64 = 2048;
    std::env::var("HELIODON_CACHE_MAX_MB").ok().and_then(|v| v.trim().parse::<u64>().ok()).unwrap_or(DEFAULT_MIB) << 20
}

/// Temporary files older than this were left by a process that died while writing.
const STALE_TEMPORARY: Duration = Duration::from_secs(3600);

/// Keeps `dir` within `limit` bytes: removes temporary files left by
/// processes that died mid-write, then the least recently used cache files
/// (never `keep`, the one just written).
pub fn tidy(dir: &Path, keep: &Path, limit: u64) {
    let Ok(entries) = fs::read_dir(dir) else { return };
    let now = SystemTime::now();
    let mut files: Vec<(SystemTime, u64, PathBuf)> = Vec::new();
    for entry in entries.flatten() {
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().into_owned();
        let Ok(meta) = entry.metadata() else { continue };
        let modified = meta.modified().unwrap_or(now);
        if !name.starts_with("light-") || !meta.is_file() {
            continue;
        }
        if name.contains(".tmp") {
            if now.duration_since(modified).unwrap_or_default() > STALE_TEMPORARY {
                let _ = fs::remove_file(&path);
            }
            continue;
        }
        files.push((modified, meta.len(), path));
    }
    let mut total: u64 = files.iter().map(|f| f.1).sum();
    files.sort();
    for (_, size, path) in files {
        if total <= limit {
            break;
        }
        if path != keep && fs::remove_file(&path).is_ok() {
            total -= size;
        }
    }
}

/// The bytes before a file's payload: magic, format, key, the payload's
/// length and its checksum.
const HEADER: usize = 36;

fn header(key: u64, len: u64, checksum: u64) -> [u8; HEADER] {
    let mut out = [0; HEADER];
    out[..8].copy_from_slice(MAGIC);
    out[8..12].copy_from_slice(&FORMAT.to_le_bytes());
    out[12..20].copy_from_slice(&key.to_le_bytes());
    out[20..28].copy_from_slice(&len.to_le_bytes());
    out[28..].copy_from_slice(&checksum.to_le_bytes());
    out
}

/// The payload's length and checksum a header gives, when it is a light
/// cache of this format stored under `key`.
fn read_header(bytes: &[u8], key: u64) -> Result<(u64, u64), String> {
    if bytes.len() < HEADER || &bytes[..8] != MAGIC {
        return Err("not a heliodon light cache".into());
    }
    let u32_at = |i: usize| u32::from_le_bytes(bytes[i..i + 4].try_into().expect("4 bytes"));
    let u64_at = |i: usize| u64::from_le_bytes(bytes[i..i + 8].try_into().expect("8 bytes"));
    if u32_at(8) != FORMAT {
        return Err(format!("format {} (expected {FORMAT})", u32_at(8)));
    }
    if u64_at(12) != key {
        return Err("key mismatch".into());
    }
    Ok((u64_at(20), u64_at(28)))
}

/// Writes the header and `payload` to `path`, the payload as it is: not
/// copied behind the header in memory first (a large model's payload is
/// hundreds of megabytes).
fn write_file(path: &Path, payload: &[u8], key: u64) -> io::Result<()> {
    let mut file = fs::File::create(path)?;
    file.write_all(&header(key, payload.len() as u64, StableHash::new().bytes(payload).finish()))?;
    file.write_all(payload)
}

fn decode(bytes: &[u8], key: u64) -> Result<&[u8], String> {
    let header = read_header(bytes, key)?;
    let payload = &bytes[HEADER..];
    check_payload(header, payload.len() as u64, StableHash::new().bytes(payload).finish())?;
    Ok(payload)
}

/// Whether the payload read (its length and checksum) is the one the
/// header gives.
fn check_payload((len, checksum): (u64, u64), read_len: u64, read_checksum: u64) -> Result<(), String> {
    if read_len != len {
        return Err("truncated".into());
    }
    if read_checksum != checksum {
        return Err("checksum mismatch".into());
    }
    Ok(())
}

/// Little-endian writer of the payload.
#[derive(Default)]
pub(crate) struct Writer(pub Vec<u8>);

impl Writer {
    pub fn u8(&mut self, v: u8) {
        self.0.push(v);
    }

    pub fn u16(&mut self, v: u16) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }

    pub fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }

    pub fn f32(&mut self, v: f32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }

    pub fn f64(&mut self, v: f64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }

    pub fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }

    /// Flags, eight to a byte (their count is the reader's to know).
    pub fn flags(&mut self, flags: &[bool]) {
        for byte in flags.chunks(8) {
            self.u8(byte.iter().enumerate().fold(0, |b, (k, &f)| b | (u8::from(f) << k)));
        }
    }

    pub fn vec3(&mut self, v: DVec3) {
        self.f64(v.x);
        self.f64(v.y);
        self.f64(v.z);
    }

    /// A LEB128 variable-length integer (small numbers take one byte).
    pub fn varint(&mut self, mut v: u32) {
        while v >= 0x80 {
            self.0.push((v as u8) | 0x80);
            v >>= 7;
        }
        self.0.push(v as u8);
    }

    /// Sparse rows sorted by index: each index as its step from the one
    /// before (mostly one or two bytes), each share bit-exact. A share that
    /// is a whole number of the row's unit (2^-p: most are k rays of 2^p,
    /// as 256 per patch side) is that number; others are the float as it is.
    pub fn pairs(&mut self, pairs: &[(u32, f32)]) {
        self.u32(pairs.len() as u32);
        let bits = pairs.iter().filter_map(|&(_, w)| fraction_bits(w)).max().unwrap_or(0);
        self.0.push(bits as u8);
        let unit = (-(bits as f32)).exp2();
        // Dividing by a power of two is exact: whole numbers of units stay whole.
        let units = |w: f32| {
            let units = w / unit;
            (fraction_bits(w).is_some() && units < FRACTION_UNITS && (units as u32) as f32 * unit == w).then_some(units as u32)
        };
        let mut previous = 0;
        for &(i, w) in pairs {
            self.varint(i - previous);
            previous = i;
            match units(w) {
                // Code k + 1: k units; 0: the float follows.
                Some(k) => self.varint(k + 1),
                None => {
                    self.varint(0);
                    self.f32(w);
                }
            }
        }
    }

    pub fn gather(&mut self, g: &Gather) {
        self.pairs(&g.daylight_coefficients);
        self.pairs(&g.form_factors);
        // Most sides have nothing buried: one byte.
        if g.buried == 0.0 {
            self.varint(0);
        } else {
            self.varint(1);
            self.f32(g.buried);
        }
    }
}

/// The finest unit a row's shares are counted in, 2^-24.
const MAX_FRACTION_BITS: u32 = 24;
/// Whole numbers of units up to here are exact as floats.
const FRACTION_UNITS: f32 = (1u32 << 24) as f32;

/// The binary fraction digits `share` needs when it is a whole number of
/// units of 2^-24 or coarser (a ray count over a power-of-two number of
/// rays); `None` otherwise (light through glass, aimed rays).
fn fraction_bits(share: f32) -> Option<u32> {
    if !share.is_normal() || share < 0.0 {
        return (share == 0.0 && share.is_sign_positive()).then_some(0);
    }
    let bits = share.to_bits();
    let mantissa = (bits & 0x7f_ffff) | 0x80_0000;
    let exponent = ((bits >> 23) & 0xff) as i32 - 127;
    let fraction = (23 - mantissa.trailing_zeros() as i32 - exponent).max(0) as u32;
    (fraction <= MAX_FRACTION_BITS).then_some(fraction)
}

/// Reader of the payload; `None` when it runs out.
pub(crate) struct Reader<'a>(pub &'a [u8]);

impl Reader<'_> {
    fn take(&mut self, n: usize) -> Option<&[u8]> {
        if self.0.len() < n {
            return None;
        }
        let (head, tail) = self.0.split_at(n);
        self.0 = tail;
        Some(head)
    }

    pub fn u8(&mut self) -> Option<u8> {
        self.take(1).map(|b| b[0])
    }

    pub fn u16(&mut self) -> Option<u16> {
        self.take(2).map(|b| u16::from_le_bytes(b.try_into().expect("2 bytes")))
    }

    pub fn u32(&mut self) -> Option<u32> {
        self.take(4).map(|b| u32::from_le_bytes(b.try_into().expect("4 bytes")))
    }

    pub fn f32(&mut self) -> Option<f32> {
        self.take(4).map(|b| f32::from_le_bytes(b.try_into().expect("4 bytes")))
    }

    pub fn f64(&mut self) -> Option<f64> {
        self.take(8).map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
    }

    pub fn u64(&mut self) -> Option<u64> {
        self.take(8).map(|b| u64::from_le_bytes(b.try_into().expect("8 bytes")))
    }

    /// `count` flags as [`Writer::flags`] wrote them.
    pub fn flags(&mut self, count: usize) -> Option<Vec<bool>> {
        let bytes = self.take(count.div_ceil(8))?;
        Some((0..count).map(|k| bytes[k / 8] >> (k % 8) & 1 == 1).collect())
    }

    pub fn vec3(&mut self) -> Option<DVec3> {
        Some(DVec3::new(self.f64()?, self.f64()?, self.f64()?))
    }

    pub fn varint(&mut self) -> Option<u32> {
        let mut v: u32 = 0;
        for shift in (0..35).step_by(7) {
            let byte = *self.take(1)?.first()?;
            v |= u32::from(byte & 0x7f).checked_shl(shift)?;
            if byte & 0x80 == 0 {
                return Some(v);
            }
        }
        None
    }

    pub fn pairs(&mut self) -> Option<Vec<(u32, f32)>> {
        let n = self.u32()? as usize;
        let bits = *self.take(1)?.first()?;
        if n > self.0.len() / 2 || u32::from(bits) > MAX_FRACTION_BITS {
            return None;
        }
        let unit = (-f32::from(bits)).exp2();
        let mut previous: u32 = 0;
        (0..n)
            .map(|_| {
                previous = previous.checked_add(self.varint()?)?;
                let share = match self.varint()? {
                    0 => self.f32()?,
                    units => (units - 1) as f32 * unit,
                };
                Some((previous, share))
            })
            .collect()
    }

    pub fn gather(&mut self) -> Option<Gather> {
        let (daylight_coefficients, form_factors) = (self.pairs()?, self.pairs()?);
        let buried = match self.varint()? {
            0 => 0.0,
            1 => self.f32()?,
            _ => return None,
        };
        Some(Gather { daylight_coefficients, form_factors, buried })
    }

    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

/// What a model gathered: per patch side, and its sensors (with the key of
/// the model they are shared with, if they are); and which of each are open
/// to the sun ([`super::openings::Spaces`]).
type Gathered = (Vec<Arc<Gather>>, (Arc<Vec<SensorGeometry>>, Option<u64>), (Vec<bool>, Vec<bool>));

impl LightModel {
    /// The gathered data, for the cache.
    fn save(&self, out: &mut BlockWriter) -> io::Result<()> {
        // The shadow tracer first, a block of its own: a model beside
        // another skips it (it shares the other's).
        out.bytes(&self.shadow_tracer.to_bytes())?;
        out.block(|w| {
            w.u32(self.side_gathers.len() as u32);
            w.u32(self.sensors.len() as u32);
            // Sensors shared with another model: its key, not them again.
            match self.sensors_of {
                Some(key) => {
                    w.u8(1);
                    w.u64(key);
                }
                None => w.u8(0),
            }
        })?;
        out.items(&self.side_gathers, GATHERS_PER_BLOCK, |w, g| w.gather(g))?;
        if self.sensors_of.is_none() {
            out.items(&self.sensors, SENSORS_PER_BLOCK, |w, s| s.write(w))?;
        }
        out.block(|w| {
            w.flags(&self.open_sides);
            w.flags(&self.open_sensors);
        })
    }

    /// The model a file's blocks hold, if it fits the scene: its shadow
    /// tracer read back (or `beside`'s, shared), its gathers and sensors.
    fn read_cached(scene: &Arc<Scene>, settings: LightSettings, beside: Option<&LightModel>, blocks: &mut Blocks) -> Option<Self> {
        let tracer_bytes = blocks.next()?;
        // A model beside of the same scene lends its shadow tracer (`empty`
        // takes it); else the stored one is read.
        let stored = if beside.is_some_and(|b| Arc::ptr_eq(&b.scene, scene)) {
            None
        } else {
            let (triangles, owner) = LightModel::shadow_casters(scene);
            Some(Arc::new(Tracer::from_bytes(&tracer_bytes, &triangles, &owner)?))
        };
        drop(tracer_bytes);
        let beside = beside.filter(|b| Arc::ptr_eq(&b.scene, scene));
        let (side_gathers, (sensors, sensors_of), (open_sides, open_sensors)) = Self::read_payload(scene, settings, beside, blocks)?;
        let empty = Self::empty(scene.clone(), settings, beside, stored);
        Some(LightModel { side_gathers, sensors, sensors_of, open_sides, open_sensors, ..empty }.sharing(beside))
    }

    /// The side gathers and sensor geometries a file's blocks hold after
    /// its tracer, if they fit the scene; sensors it holds as those of
    /// another model, `beside`'s when it is that model (else it does not fit).
    fn read_payload(scene: &Scene, settings: LightSettings, beside: Option<&LightModel>, blocks: &mut Blocks) -> Option<Gathered> {
        let counts = blocks.next()?;
        let mut r = Reader(&counts);
        let (sides, sensor_count) = (r.u32()? as usize, r.u32()? as usize);
        let sensors_of = match r.u8()? {
            0 => None,
            1 => Some(r.u64()?),
            _ => return None,
        };
        if !r.is_empty() || sides != scene.patches.patches.len() * 2 || sensor_count != scene.sensors.len() {
            return None;
        }
        let side_gathers = blocks.items(sides, |r| r.gather())?;
        let sensors = match sensors_of {
            None => Arc::new(blocks.items(sensor_count, SensorGeometry::read)?),
            Some(key) => beside.filter(|b| b.cache_key.get() == Some(&key))?.sensors.clone(),
        };
        let flags = blocks.next()?;
        let mut r = Reader(&flags);
        let open = (r.flags(sides)?, r.flags(sensor_count)?);
        let bins = (scene.windows.len() as u32 + 1) * 2 * SkyPatches::reinhart(settings.sky_subdivision).len() as u32;
        let patch_sides = sides as u32;
        let fits = |g: &Gather| g.daylight_coefficients.iter().all(|b| b.0 < bins) && g.form_factors.iter().all(|s| s.0 < patch_sides);
        let hits_fit = |s: &SensorGeometry| s.landings.fits(patch_sides);
        let sensors_fit = sensors_of.is_some() || sensors.iter().all(|s| fits(&s.gather) && hits_fit(s));
        if !r.is_empty() || !side_gathers.iter().all(fits) || !sensors_fit {
            return None;
        }
        let nothing = Arc::new(Gather::default());
        let shared = |g: Gather| if g == *nothing { nothing.clone() } else { Arc::new(g) };
        Some((side_gathers.into_iter().map(shared).collect(), (sensors, sensors_of), open))
    }

    /// This model (read from the cache) with what it has alike with
    /// `beside` held once: its sides and sensors equal to `beside`'s.
    fn sharing(mut self, beside: Option<&LightModel>) -> Self {
        let Some(beside) = beside.filter(|b| Arc::ptr_eq(&b.scene, &self.scene)) else {
            return self;
        };
        for (own, theirs) in self.side_gathers.iter_mut().zip(&beside.side_gathers) {
            if own == theirs {
                *own = theirs.clone();
            }
        }
        if !Arc::ptr_eq(&self.sensors, &beside.sensors) && self.sensors == beside.sensors {
            self.sensors = beside.sensors.clone();
        }
        self
    }
}

impl Landings {
    /// Each run as its side's step from the last and its length; the
    /// shares run-length coded (most are 1/rays); the points per run, each
    /// coordinate its points share (on a patch square to an axis, as most
    /// of a building's are, one of the three) written once.
    fn write(&self, w: &mut Writer) {
        let (runs, shares) = self.parts();
        w.u32(runs.len() as u32);
        let (mut side, mut end) = (0, 0);
        for &(s, e) in runs {
            w.varint(s - side);
            w.varint(e - end);
            (side, end) = (s, e);
        }
        w.u32(shares.len() as u32);
        for &(count, value) in shares {
            w.varint(count);
            w.f32(value);
        }
        for (run, coords) in self.run_coordinates() {
            w.u8(run.shared);
            (0..3).filter(|&axis| run.shared & (1 << axis) != 0).for_each(|axis| w.u16(run.first[axis]));
            coords.iter().for_each(|&c| w.u16(c));
        }
    }

    fn read(r: &mut Reader) -> Option<Self> {
        let count = |r: &mut Reader, least_bytes: usize| r.u32().map(|n| n as usize).filter(|&n| n <= r.0.len() / least_bytes);
        let (mut side, mut end) = (0u32, 0u32);
        let runs = (0..count(r, 2)?)
            .map(|_| {
                side = side.checked_add(r.varint()?)?;
                end = end.checked_add(r.varint()?)?;
                Some((side, end))
            })
            .collect::<Option<Vec<_>>>()?;
        let total = end as usize;
        let shares = (0..count(r, 5)?).map(|_| Some((r.varint()?, r.f32()?))).collect::<Option<Vec<_>>>()?;
        // A count past the landings is refused before points are read for it.
        if shares.iter().try_fold(0usize, |sum, &(count, _)| sum.checked_add(count as usize)).is_none_or(|sum| sum != total) {
            return None;
        }
        let (mut run_points, mut coords) = (Vec::with_capacity(runs.len()), Vec::with_capacity((2 * total).min(r.0.len() / 2)));
        let mut start = 0;
        for &(_, end) in &runs {
            if end < start || end as usize > total {
                return None;
            }
            let mut run = RunPoints { shared: r.u8().filter(|&bits| bits < 8)?, first: [0; 3] };
            for axis in (0..3).filter(|&axis| run.shared & (1 << axis) != 0) {
                run.first[axis] = r.u16()?;
            }
            for _ in 0..(end - start) as usize * run.own_axes().count() {
                coords.push(r.u16()?);
            }
            run_points.push(run);
            start = end;
        }
        Self::from_parts(runs, shares, run_points, coords)
    }
}

impl SensorGeometry {
    pub(super) fn write(&self, w: &mut Writer) {
        w.u32(self.sun_points.len() as u32);
        self.sun_points.iter().for_each(|&p| w.vec3(p));
        w.vec3(self.normal);
        w.gather(&self.gather);
        self.landings.write(w);
    }

    pub(super) fn read(r: &mut Reader) -> Option<Self> {
        let count = |r: &mut Reader, size: usize| r.u32().map(|n| n as usize).filter(|&n| n <= r.0.len() / size);
        let n = count(r, 24)?;
        let sun_points = (0..n).map(|_| r.vec3()).collect::<Option<Vec<_>>>()?;
        let normal = r.vec3()?;
        let gather = r.gather()?;
        Some(Self::new(gather, sun_points, normal, Landings::read(r)?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stream hashes the same however it is split (the streamed writer's
    /// checksum is the whole file's), and a byte changed, moved or
    /// appended anywhere (a zero at the end too) changes the hash.
    #[test]
    fn the_stable_hash_follows_the_bytes_not_the_pieces() {
        let data: Vec<u8> = (0..100u32).map(|k| (k * 37 % 251) as u8).collect();
        let whole = StableHash::new().bytes(&data).finish();
        for split in [1, 3, 7, 8, 9, 50, 99] {
            let (a, b) = data.split_at(split);
            assert_eq!(StableHash::new().bytes(a).bytes(b).finish(), whole, "split at {split}");
        }
        let byte_by_byte = data.iter().fold(StableHash::new(), |mut h, b| {
            h.bytes(&[*b]);
            h
        });
        assert_eq!(byte_by_byte.finish(), whole);
        let mut changed = data.clone();
        changed[42] ^= 1;
        let mut swapped = data.clone();
        swapped.swap(0, 1);
        let mut longer = data.clone();
        longer.push(0);
        for other in [changed, swapped, longer, data[..99].to_vec()] {
            assert_ne!(StableHash::new().bytes(&other).finish(), whole);
        }
        // The values are what the keys are made of: numbers by their bytes.
        let floats = [1.5f32, -2.0, 3.25];
        let bytes: Vec<u8> = floats.iter().flat_map(|v| v.to_bits().to_le_bytes()).collect();
        assert_eq!(StableHash::new().f32s(&floats).finish(), StableHash::new().bytes(&bytes).finish());
        assert_eq!(StableHash::new().u64(7).finish(), StableHash::new().bytes(&7u64.to_le_bytes()).finish());
        // Four-byte values after an odd number of bytes, too.
        let mixed = StableHash::new().bytes(&[1, 2, 3]).u32(9).f32s(&floats).u32(4).finish();
        let as_bytes: Vec<u8> = [vec![1, 2, 3], 9u32.to_le_bytes().to_vec(), bytes.clone(), 4u32.to_le_bytes().to_vec()].concat();
        assert_eq!(mixed, StableHash::new().bytes(&as_bytes).finish());
    }

    /// A sensor's landings read back as written, the points on a flat
    /// patch in two coordinates each and those on a tilted one in three; a
    /// cut payload is refused.
    #[test]
    fn landings_are_read_back_as_written() {
        use super::super::landings::PatchBox;
        let mut boxes = vec![PatchBox::around(&[[glam::Vec3::ZERO, glam::Vec3::X, glam::Vec3::Y]]); 4];
        boxes[3] = PatchBox::around(&[[glam::Vec3::ZERO, glam::Vec3::new(1.0, 0.0, 1.0), glam::Vec3::new(0.0, 1.0, 1.0)]]);
        let p = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        let tilted = |x: f64, y: f64| DVec3::new(x, y, x + y);
        let raw = vec![
            (5, 0.5, p(0.1, 0.2)),
            (1, 0.25, p(0.3, 0.3)),
            (5, 0.5, p(0.9, 0.05)),
            (2, 0.125, p(0.0, 1.0)),
            (7, 0.5, tilted(0.2, 0.1)),
            (7, 0.5, tilted(0.4, 0.5)),
        ];
        let landings = Landings::new(raw.clone(), &boxes);
        let sides: Vec<(u32, usize)> = landings.by_side().map(|(side, shares, _)| (side, shares.len())).collect();
        assert_eq!(sides, [(1, 1), (2, 1), (5, 2), (7, 2)]);
        // Each point comes back on its grid, its shared axes held once.
        let mut sorted = raw;
        sorted.sort_by_key(|l| l.0);
        let grid: Vec<[u16; 3]> = sorted.iter().map(|&(side, _, p)| boxes[side as usize / 2].grid(p)).collect();
        assert_eq!(landings.by_side().flat_map(|(_, _, points)| points).collect::<Vec<_>>(), grid);
        let mut w = Writer::default();
        landings.write(&mut w);
        // Runs: count, then a side step and an end step each; shares: count,
        // then 0.25, 0.125 and 0.5 four times, each a count and the value;
        // points: per run its shared axes, then sides 1 and 2 one point
        // each wholly shared, side 5 two sharing z, side 7 two sharing none.
        let points = 4 + 6 + 6 + (2 + 2 * 4) + 2 * 6;
        assert_eq!(w.0.len(), (4 + 4 * 2) + (4 + 3 * 5) + points);
        let mut r = Reader(&w.0);
        assert_eq!(Landings::read(&mut r), Some(landings.clone()));
        assert!(r.is_empty());
        assert!(Landings::read(&mut Reader(&w.0[..w.0.len() - 1])).is_none(), "a cut payload is refused");
        assert!(landings.fits(8) && !landings.fits(7));
    }

    /// Rows read back bit for bit: shares counted in rays of a power of
    /// two, others (through glass), zeros of both signs, tiny and large ones.
    #[test]
    fn sparse_rows_read_back_bit_for_bit() {
        let rows: [&[(u32, f32)]; 4] = [
            &[(0, 1.0 / 256.0), (3, 7.0 / 256.0), (9, 0.37 * 0.25), (700, 255.0 / 256.0)],
            &[(2, 0.0), (5, -0.0), (6, f32::MIN_POSITIVE / 8.0), (40_000, 3.5), (40_001, 1.0 / 16384.0)],
            &[(1, 0.3), (2, 0.7)],
            &[],
        ];
        let mut w = Writer::default();
        rows.iter().for_each(|row| w.pairs(row));
        let compact = w.0.len();
        let mut r = Reader(&w.0);
        for row in rows {
            let back = r.pairs().unwrap();
            let bits = |row: &[(u32, f32)]| row.iter().map(|&(i, s)| (i, s.to_bits())).collect::<Vec<_>>();
            assert_eq!(bits(&back), bits(row));
        }
        assert!(r.is_empty());
        // A share of k rays takes one byte, not four.
        let mut w = Writer::default();
        w.pairs(&(0..100).map(|i| (i, (i % 50 + 1) as f32 / 256.0)).collect::<Vec<_>>());
        assert_eq!(w.0.len(), 4 + 1 + 100 * 2);
        assert!(compact < 4 * 4 + 4 + 11 * 5);
    }

    /// The folder stays under its bound: least recently used files go
    /// first, never the one just written; stale temporary files go too.
    #[test]
    fn the_folder_is_kept_under_its_bound() {
        let dir = std::env::temp_dir().join(format!("heliodon-cache-tidy-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        let now = SystemTime::now();
        let file = |name: &str, bytes: usize, age_s: u64| {
            let path = dir.join(name);
            fs::write(&path, vec![0u8; bytes]).unwrap();
            fs::File::options().append(true).open(&path).unwrap().set_modified(now - Duration::from_secs(age_s)).unwrap();
            path
        };
        let oldest = file("light-0000000000000001.bin", 1000, 300);
        let older = file("light-0000000000000002.bin", 1000, 200);
        let newest = file("light-0000000000000003.bin", 1000, 100);
        let written = file("light-0000000000000004.bin", 1000, 400);
        let stale = file("light-0000000000000005.tmp42", 10, 7200);
        let fresh = file("light-0000000000000006.tmp43", 10, 10);
        let other = file("notes.txt", 5000, 9000);
        tidy(&dir, &written, 2500);
        let exists = |p: &PathBuf| p.exists();
        assert!(!exists(&oldest) && !exists(&older), "the least recently used go");
        assert!(exists(&newest) && exists(&written), "the newest and the one just written stay");
        assert!(!exists(&stale) && exists(&fresh), "only stale temporary files go");
        assert!(exists(&other), "files that are not the cache's are left alone");
        let _ = fs::remove_dir_all(&dir);
    }
}
