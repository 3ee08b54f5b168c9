//! A packet's lanes packed in slots, for the shading passes that compute lanes side by side
//! (the diffuse lanes, the rough glass and mirror lanes, the environment map's): the lanes a
//! pass needs take the first slots in the order they come, so that the pass computes as many
//! groups of [`GROUP`] slots as they fill (`in_groups!`), not the whole packet (a packet
//! with a third of its paths on diffuse surfaces costs half the work).

use crate::packet::{Lanes, PACKET};

/// Slots a side-by-side pass computes at once: one AVX2 register of `f32`s.
pub const GROUP: usize = 8;

/// Which lanes of a packet have slots, and where: slot `k` of the first [`Slots::count`]
/// holds lane [`Slots::lane`]`(k)`, and lane `l`, once it has one, sits in
/// [`Slots::slot`]`(l)`.
#[derive(Debug, Clone, Copy)]
pub struct Slots {
    /// Bit `l` set: lane `l` has a slot.
    pub mask: Lanes,
    count: usize,
    /// Lane `l`'s slot.
    slot_of: [u8; PACKET],
    /// Slot `k`'s lane.
    lane_of: [u8; PACKET],
}

impl Default for Slots {
    fn default() -> Self {
        Self {
            mask: 0,
            count: 0,
            slot_of: [0; PACKET],
            lane_of: [0; PACKET],
        }
    }
}

impl Slots {
    /// The lanes of `lanes` in slots, in lane order, calling `put(l, k)` as lane `l` takes
    /// slot `k`.
    #[inline(always)]
    pub fn packed(lanes: Lanes, mut put: impl FnMut(usize, usize)) -> Self {
        let mut slots = Self::default();
        let mut left = lanes;
        while left != 0 {
            let l = left.trailing_zeros() as usize;
            left &= left - 1;
            put(l, slots.take(l));
        }
        slots
    }

    /// No lane has a slot.
    #[inline(always)]
    pub fn clear(&mut self) {
        self.mask = 0;
        self.count = 0;
    }

    /// Lane `l`, which has no slot, takes the next: returns it.
    #[inline(always)]
    pub fn take(&mut self, l: usize) -> usize {
        let k = self.count;
        self.slot_of[l] = k as u8;
        self.lane_of[k] = l as u8;
        self.count += 1;
        self.mask |= 1 << l;
        k
    }

    /// Lane `l`'s slot, taken now if it has none.
    #[inline(always)]
    pub fn slot_or_take(&mut self, l: usize) -> usize {
        if self.mask >> l & 1 == 0 {
            self.take(l)
        } else {
            self.slot(l)
        }
    }

    /// The slot of lane `l`, which has one.
    #[inline(always)]
    pub fn slot(&self, l: usize) -> usize {
        usize::from(self.slot_of[l])
    }

    /// The lane in slot `k`, one of the first [`Slots::count`].
    #[inline(always)]
    pub fn lane(&self, k: usize) -> usize {
        usize::from(self.lane_of[k])
    }

    /// How many slots are in use.
    #[inline(always)]
    pub fn count(&self) -> usize {
        self.count
    }
}

/// Evaluates `$body` with the constant `$n` set to the number of slots that `$count` slots
/// in use fill in groups of [`GROUP`]: 8, 16, 24 or 32, a count the body's loops know (one
/// copy of it per count); nothing when `$count` is 0.
macro_rules! in_groups {
    ($count:expr, $n:ident => $body:expr) => {
        match $count.div_ceil($crate::slots::GROUP) {
            0 => {}
            1 => {
                const $n: usize = $crate::slots::GROUP;
                $body
            }
            2 => {
                const $n: usize = 2 * $crate::slots::GROUP;
                $body
            }
            3 => {
                const $n: usize = 3 * $crate::slots::GROUP;
                $body
            }
            _ => {
                const $n: usize = $crate::packet::PACKET;
                $body
            }
        }
    };
}
pub(crate) use in_groups;

#[cfg(test)]
mod tests {
    use super::*;

    /// Lanes taken one by one or packed keep both ways round in step, in the order taken.
    #[test]
    fn slots_map_lanes_and_slots_both_ways() {
        let lanes: Lanes = 0b1010_0000_0000_0000_0001_0000_1100_0001;
        let mut put = Vec::new();
        let packed = Slots::packed(lanes, |l, k| put.push((l, k)));
        assert_eq!(put, [(0, 0), (6, 1), (7, 2), (12, 3), (29, 4), (31, 5)]);
        assert_eq!((packed.mask, packed.count()), (lanes, 6));
        let mut taken = Slots::default();
        for l in [9, 3, 30] {
            let k = taken.count();
            assert_eq!(taken.slot_or_take(l), k);
        }
        assert_eq!(taken.slot_or_take(3), 1);
        for (slots, order) in [(packed, &[0, 6, 7, 12, 29, 31][..]), (taken, &[9, 3, 30])] {
            for (k, &l) in order.iter().enumerate() {
                assert_eq!((slots.lane(k), slots.slot(l)), (l, k));
            }
        }
        taken.clear();
        assert_eq!((taken.mask, taken.count()), (0, 0));
        assert_eq!(taken.take(5), 0);
    }

    /// Every count of slots in use is computed by the smallest multiple of eight above it.
    #[test]
    fn in_groups_rounds_the_count_up_to_groups_of_eight() {
        for count in 0..=PACKET {
            let mut computed = 0;
            in_groups!(count, N => computed = N);
            let groups = count.div_ceil(GROUP) * GROUP;
            assert_eq!(computed, groups, "count {count}");
        }
    }
}
