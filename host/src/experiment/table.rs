//! The host's weight table: a plain slice (exact or hashed layouts), a
//! claim table of Q16 weights with 32-bit tags (the host's LEO,
//! [`pada_core::claim_table`]), or the chips' LEO claim table of 16-bit
//! weights and 16-bit tags (to build a board's learner on the host),
//! behind one type so that every host agent is one
//! [`crate::experiment::HostAgent`].
//!
//! Each access matches on the kind once; the branch goes the same way for
//! a whole run, so it costs next to nothing against the table read behind
//! it.

use pada_core::claim_table::{Claim, ClaimTable, InitialWeights, Occupancy, Tags16, Tags32, WhenFull};
use pada_core::fixed::Q16;
use pada_core::weights::{Added, Half, WeightFormat, WeightStore};

/// A claim table on the heap: Q16 weights, 32-bit tags.
pub type HostClaimTable = ClaimTable<Box<[Q16]>, Tags32<Box<[u32]>>>;

/// The shift of the chips' 16-bit LEO weights.
const LEO_SHIFT: u32 = pada_core::robot::leo::HALF_SHIFT as u32;

/// The chips' LEO claim table on the heap: 16-bit weights, 16-bit tags.
pub type ChipClaimTable = ClaimTable<Half<Box<[i16]>, LEO_SHIFT>, Tags16<Box<[u16]>>>;

/// The host's table.
#[derive(Debug, Clone)]
pub enum HostTable {
    /// One weight per index (the exact and hashed layouts).
    Plain(Box<[Q16]>),
    /// A claim table.
    Claimed(HostClaimTable),
    /// The chips' LEO claim table.
    Chip(ChipClaimTable),
    /// One 16-bit weight per index: the F405's hashed table (its two
    /// memories are one slice here, as `Split` addresses them).
    Half(Half<Box<[i16]>, LEO_SHIFT>),
}

impl HostTable {
    /// A plain table of `n` zero weights.
    pub fn plain(n: usize) -> HostTable {
        HostTable::Plain(vec![Q16::ZERO; n].into_boxed_slice())
    }

    /// A plain table of `n` zero weights in `format`: Q16, or the chips'
    /// 16-bit weights shifted by LEO's shift (no other is built on the
    /// host).
    pub fn plain_of(n: usize, format: WeightFormat) -> anyhow::Result<HostTable> {
        match format {
            WeightFormat::Q16 => Ok(HostTable::plain(n)),
            WeightFormat::Half { shift } if shift as u32 == LEO_SHIFT => {
                Ok(HostTable::Half(Half::new(vec![0i16; n].into_boxed_slice())))
            }
            _ => anyhow::bail!("no host table of {format:?} weights (Q16, or 16-bit weights shifted by {LEO_SHIFT})"),
        }
    }

    /// A claim table of `n` free slots (`n` a power of two): Q16 weights
    /// with 32-bit tags, or LEO's 16-bit weights with 16-bit tags (the
    /// chips'); no other combination is built on the host.
    pub fn claimed(n: usize, format: WeightFormat, tag_bytes: usize) -> anyhow::Result<HostTable> {
        let err = |e: pada_core::claim_table::ClaimTableError| anyhow::anyhow!("{e}");
        match (format, tag_bytes) {
            (WeightFormat::Q16, 4) => {
                let weights = vec![Q16::ZERO; n].into_boxed_slice();
                let tags = Tags32(vec![0u32; n].into_boxed_slice());
                Ok(HostTable::Claimed(ClaimTable::new(weights, tags).map_err(err)?))
            }
            (WeightFormat::Half { shift }, 2) if shift as u32 == LEO_SHIFT => {
                let weights = Half::new(vec![0i16; n].into_boxed_slice());
                let tags = Tags16(vec![0u16; n].into_boxed_slice());
                Ok(HostTable::Chip(ClaimTable::new(weights, tags).map_err(err)?))
            }
            _ => anyhow::bail!(
                "no host claim table with {format:?} weights and {}-bit tags (Q16 with 32-bit tags, or 16-bit weights \
                 shifted by {LEO_SHIFT} with 16-bit tags)",
                tag_bytes * 8
            ),
        }
    }
}

impl HostTable {
    /// The same table, a claim table doing `when_full` with a claim that
    /// finds it full (nothing for a plain table).
    pub fn on_full(self, when_full: WhenFull) -> HostTable {
        match self {
            HostTable::Plain(t) => HostTable::Plain(t),
            HostTable::Claimed(t) => HostTable::Claimed(t.on_full(when_full)),
            HostTable::Chip(t) => HostTable::Chip(t.on_full(when_full)),
            HostTable::Half(t) => HostTable::Half(t),
        }
    }
}

macro_rules! each {
    ($self:expr, $t:ident => $e:expr) => {
        match $self {
            HostTable::Plain($t) => $e,
            HostTable::Claimed($t) => $e,
            HostTable::Chip($t) => $e,
            HostTable::Half($t) => $e,
        }
    };
}

impl WeightStore for HostTable {
    fn len(&self) -> usize {
        each!(self, t => WeightStore::len(t))
    }

    #[inline]
    fn get(&self, i: usize) -> Q16 {
        each!(self, t => t.get(i))
    }

    #[inline]
    fn set(&mut self, i: usize, w: Q16) {
        each!(self, t => t.set(i, w))
    }

    #[inline]
    fn add(&mut self, i: usize, inc: Q16, dither: u32) -> bool {
        each!(self, t => t.add(i, inc, dither))
    }

    fn format(&self) -> WeightFormat {
        each!(self, t => t.format())
    }

    fn stored_le(&self, i: usize, out: &mut [u8]) {
        each!(self, t => t.stored_le(i, out))
    }

    fn load_le(&mut self, i: usize, bytes: &[u8]) {
        each!(self, t => t.load_le(i, bytes))
    }

    #[inline]
    fn raw(&self, i: usize) -> u32 {
        each!(self, t => t.raw(i))
    }

    #[inline]
    fn dithered(&self) -> bool {
        each!(self, t => t.dithered())
    }

    #[inline]
    fn claims(&self) -> bool {
        !matches!(self, HostTable::Plain(_) | HostTable::Half(_))
    }

    fn tag_bytes(&self) -> usize {
        each!(self, t => t.tag_bytes())
    }

    #[inline]
    fn read(&self, feature: u32) -> Q16 {
        each!(self, t => WeightStore::read(t, feature))
    }

    #[inline]
    fn read_each(&self, buf: &mut [u32]) {
        each!(self, t => t.read_each(buf))
    }

    #[inline]
    fn claim(&mut self, feature: u32) -> Claim {
        each!(self, t => WeightStore::claim(t, feature))
    }

    #[inline]
    fn read_then_claim(&mut self, features: &[u32], claims: &mut [Claim]) -> i64 {
        each!(self, t => t.read_then_claim(features, claims))
    }

    #[inline]
    fn add_each<D: FnMut() -> u32>(&mut self, slots: &[u32], inc: Q16, dither: D) -> Added {
        each!(self, t => t.add_each(slots, inc, dither))
    }

    fn reset_claims(&mut self, init: InitialWeights) {
        each!(self, t => t.reset_claims(init))
    }

    fn restore_claims(&mut self, init: InitialWeights, refused: u32) {
        each!(self, t => t.restore_claims(init, refused))
    }

    fn occupancy(&self) -> Option<Occupancy> {
        each!(self, t => WeightStore::occupancy(t))
    }

    fn when_full(&self) -> WhenFull {
        each!(self, t => WeightStore::when_full(t))
    }

    fn table_seed(&self) -> u64 {
        each!(self, t => t.table_seed())
    }

    fn checksum(&self) -> u32 {
        each!(self, t => t.checksum())
    }
}
