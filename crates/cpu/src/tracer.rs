//! A thread's ray queries against a scene: one ray at a time (the walk of [`crate::bvh`]) or
//! packets of rays (the walk of [`crate::packet`]), with the traversal stacks every query
//! reuses, so that queries allocate nothing once they have grown to the tree's needs, and so
//! that the whole walk inlines into the caller (compiled for its instruction set).

use crate::bvh::{Entry, Hit, trace_scene};
use crate::cpu_scene::CpuScene;
use crate::intersect::Ray;
use crate::packet::{Lanes, PACKET, PacketHits, PacketRays, PacketWalk, RayPacket, Stacks};

/// Ray queries from one thread against a scene, one ray at a time or in packets.
#[derive(Debug, Clone)]
pub struct Tracer<'a> {
    /// The scene and its tree.
    pub scene: &'a CpuScene<'a>,
    /// The single-ray walk's stack.
    stack: Vec<Entry>,
    /// The packet walk's stack: nodes and the rays that entered them.
    packet_stack: Vec<(u32, Lanes)>,
    /// The rays of the packet being walked, written in place by each query (a new value
    /// each time was kilobytes set up and copied).
    rays: PacketRays,
    /// The shadow queries' hits.
    shadow_hits: PacketHits,
}

impl<'a> Tracer<'a> {
    /// Queries against `scene`.
    pub fn new(scene: &'a CpuScene<'a>) -> Self {
        Self {
            scene,
            stack: Vec::new(),
            packet_stack: Vec::new(),
            rays: PacketRays::default(),
            shadow_hits: PacketHits::default(),
        }
    }

    /// Nearest hit in `(0, t_max)`.
    #[inline(always)]
    pub fn intersect(&mut self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let hit = trace_scene(self.scene, &mut self.stack, ray, t_max, false);
        (hit.object != u32::MAX).then_some(hit)
    }

    /// Whether anything lies on the ray in `(0, t_max)`.
    #[inline(always)]
    pub fn occluded(&mut self, ray: &Ray, t_max: f32) -> bool {
        trace_scene(self.scene, &mut self.stack, ray, t_max, true).object != u32::MAX
    }

    /// Nearest hit in `(0, t_max)` of each active ray of `packet` (none for the others),
    /// into `hits`. `WIDE`: the caller's level has AVX-512 (its shape tests take sixteen
    /// lanes at once, not eight).
    #[inline(always)]
    pub fn intersect_packet<const WIDE: bool>(
        &mut self,
        packet: &RayPacket,
        hits: &mut PacketHits,
    ) {
        self.walk_packet::<WIDE>(packet, false, Some(hits));
    }

    /// Bit `l` set: something lies on active ray `l` of `packet` in `(0, t_max)`. `WIDE` as
    /// for [`Tracer::intersect_packet`].
    #[inline(always)]
    pub fn occluded_packet<const WIDE: bool>(&mut self, packet: &RayPacket) -> Lanes {
        // Only traced lanes can have found something.
        self.walk_packet::<WIDE>(packet, true, None).found()
    }

    /// Walks the active rays of `packet` through the scene's tree, for their nearest hits
    /// or (`any_hit`) any, into `hits` or else the shadow queries' own; returns those.
    #[inline(always)]
    fn walk_packet<'s, const WIDE: bool>(
        &'s mut self,
        packet: &RayPacket,
        any_hit: bool,
        hits: Option<&'s mut PacketHits>,
    ) -> &'s PacketHits {
        let hits = hits.unwrap_or(&mut self.shadow_hits);
        let active = packet.active & (Lanes::MAX >> (Lanes::BITS as usize - PACKET));
        hits.reset(packet, active);
        if !self.scene.primitives.is_empty() && active != 0 {
            self.rays.set(packet, !self.scene.triangles.is_empty());
            let walk = PacketWalk::<WIDE> {
                scene: self.scene,
                rays: &self.rays,
                any_hit,
            };
            self.packet_stack.clear();
            self.stack.clear();
            let mut stacks = Stacks {
                packet: &mut self.packet_stack,
                single: &mut self.stack,
            };
            walk.tree(&mut stacks, 0, active, hits);
        }
        hits
    }
}
