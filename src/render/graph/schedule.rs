//! Scheduling one frame's graph, without a GPU: the order the passes run in (every pass after
//! the writers of what it reads), the passes culled because nothing kept reads what they
//! write, each transient's lifetime, and which transients share one pooled resource because
//! their lifetimes do not overlap.

use crate::render::graph::GraphError;
use crate::render::graph::declare::{Declarations, PoolKey};

/// The result of scheduling; its vectors are reused from frame to frame.
#[derive(Debug, Default)]
pub struct Schedule {
    /// Passes to record, in order.
    pub order: Vec<u32>,
    /// Passes left out: nothing kept reads what they write and they have no side effect.
    pub culled: Vec<u32>,
    /// Per resource: the pooled slot a transient lives in this frame (None for imported
    /// resources and transients no kept pass uses).
    pub slot_of: Vec<Option<u32>>,
    /// Per slot: what it holds, and its ordinal among the slots of the same key.
    pub slots: Vec<(PoolKey, u32)>,
    state: Vec<u8>,
    needed: Vec<bool>,
    first: Vec<u32>,
    last: Vec<u32>,
    by_first: Vec<u32>,
    slot_free_after: Vec<u32>,
}

/// Calls `f` with every pass other than `pass` that writes a resource `pass` reads.
fn for_each_dependency(decls: &Declarations, pass: u32, mut f: impl FnMut(u32)) {
    for read in decls.accesses.iter().filter(|a| a.pass == pass && !a.write) {
        for write in decls.accesses.iter().filter(|a| a.write && a.resource == read.resource) {
            if write.pass != pass {
                f(write.pass);
            }
        }
    }
}

/// Depth-first visit: pushes `pass` after its dependencies; Err(pass) on a cycle.
fn visit(decls: &Declarations, pass: u32, state: &mut [u8], order: &mut Vec<u32>) -> Result<(), u32> {
    match state[pass as usize] {
        2 => return Ok(()),
        1 => return Err(pass),
        _ => {}
    }
    state[pass as usize] = 1;
    let mut cycle = Ok(());
    for_each_dependency(decls, pass, |d| {
        if cycle.is_ok() {
            cycle = visit(decls, d, state, order);
        }
    });
    cycle?;
    state[pass as usize] = 2;
    order.push(pass);
    Ok(())
}

impl Schedule {
    /// Schedules `decls` for passes named `names` (indexed by pass). Passes with no
    /// dependency between them keep their declaration order.
    pub fn compute(&mut self, decls: &Declarations, names: &[&'static str]) -> Result<(), GraphError> {
        self.order.clear();
        self.culled.clear();
        if let Some(error) = &decls.error {
            return Err(error.clone());
        }
        let passes = names.len();
        self.state.clear();
        self.state.resize(passes, 0);
        for pass in 0..passes as u32 {
            visit(decls, pass, &mut self.state, &mut self.order).map_err(|p| GraphError::Cycle(names[p as usize]))?;
        }
        self.cull(decls);
        self.lifetimes(decls);
        self.alias(decls);
        Ok(())
    }

    /// Keeps the passes with a side effect or a write to an imported resource, and every pass
    /// that writes what a kept pass reads.
    fn cull(&mut self, decls: &Declarations) {
        self.needed.clear();
        self.needed.extend_from_slice(&decls.side_effects);
        for a in decls.accesses.iter().filter(|a| a.write) {
            if decls.resources[a.resource as usize].transient.is_none() {
                self.needed[a.pass as usize] = true;
            }
        }
        // NOTE: dependencies come before their readers in `order`, so one backward sweep
        // reaches every pass a kept pass needs.
        for &pass in self.order.iter().rev() {
            if self.needed[pass as usize] {
                for_each_dependency(decls, pass, |d| self.needed[d as usize] = true);
            }
        }
        self.culled.clear();
        let needed = &self.needed;
        self.culled.extend(self.order.iter().filter(|&&p| !needed[p as usize]));
        self.order.retain(|&p| needed[p as usize]);
    }

    /// First and last position (in `order`) at which each resource is used.
    fn lifetimes(&mut self, decls: &Declarations) {
        let count = decls.resources.len();
        self.first.clear();
        self.first.resize(count, u32::MAX);
        self.last.clear();
        self.last.resize(count, 0);
        for (position, &pass) in self.order.iter().enumerate() {
            for a in decls.accesses.iter().filter(|a| a.pass == pass) {
                let r = a.resource as usize;
                self.first[r] = self.first[r].min(position as u32);
                self.last[r] = self.last[r].max(position as u32);
            }
        }
    }

    /// Gives each used transient a slot, sharing a slot between transients of the same key
    /// whose lifetimes do not overlap (in order of first use).
    fn alias(&mut self, decls: &Declarations) {
        self.slot_of.clear();
        self.slot_of.resize(decls.resources.len(), None);
        self.slots.clear();
        self.slot_free_after.clear();
        self.by_first.clear();
        let first = &self.first;
        self.by_first.extend(
            (0..decls.resources.len() as u32)
                .filter(|&r| decls.resources[r as usize].transient.is_some() && first[r as usize] != u32::MAX),
        );
        self.by_first.sort_by_key(|&r| first[r as usize]);
        for &r in &self.by_first {
            let (r, key) = (r as usize, decls.resources[r as usize].transient);
            let Some(key) = key else { continue };
            let free =
                (0..self.slots.len()).find(|&s| self.slots[s].0 == key && self.slot_free_after[s] < self.first[r]);
            let slot = free.unwrap_or_else(|| {
                let ordinal = self.slots.iter().filter(|(k, _)| *k == key).count() as u32;
                self.slots.push((key, ordinal));
                self.slot_free_after.push(0);
                self.slots.len() - 1
            });
            self.slot_free_after[slot] = self.last[r];
            self.slot_of[r] = Some(slot as u32);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::graph::declare::{PassBuilder, TextureDesc, TextureId};

    const NAMES: [&str; 4] = ["a", "b", "c", "d"];

    fn desc(label: &'static str, side: u32) -> TextureDesc {
        TextureDesc {
            label,
            width: side,
            height: side,
            layers: 1,
            format: wgpu::TextureFormat::Depth32Float,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            samples: 1,
        }
    }

    fn pass(decls: &mut Declarations, pass: u32) -> PassBuilder<'_> {
        PassBuilder {
            decls,
            pass,
            node: NAMES[pass as usize],
        }
    }

    fn imported(decls: &mut Declarations, label: &'static str) -> TextureId {
        TextureId(decls.add(label, None))
    }

    fn names(schedule: &[u32]) -> Vec<&'static str> {
        schedule.iter().map(|&p| NAMES[p as usize]).collect()
    }

    #[test]
    fn readers_run_after_writers_whatever_the_declaration_order() {
        let mut decls = Declarations::default();
        decls.begin(3);
        let target = imported(&mut decls, "target");
        let shadow = imported(&mut decls, "shadow map");
        // Declared post, forward, shadow: run shadow, forward, post.
        pass(&mut decls, 0).read(target);
        pass(&mut decls, 0).write(target);
        pass(&mut decls, 1).read(shadow);
        pass(&mut decls, 1).write(target);
        pass(&mut decls, 2).write(shadow);
        let mut schedule = Schedule::default();
        schedule.compute(&decls, &NAMES[..3]).unwrap();
        assert_eq!(names(&schedule.order), ["c", "b", "a"]);
        assert!(schedule.culled.is_empty());
    }

    #[test]
    fn passes_whose_output_nobody_reads_are_culled_with_their_inputs() {
        let mut decls = Declarations::default();
        decls.begin(4);
        let target = imported(&mut decls, "target");
        // a makes a texture only b reads; b writes nothing kept; c writes the target.
        let scratch = pass(&mut decls, 0).create_texture(desc("scratch", 64));
        pass(&mut decls, 1).read(scratch);
        let unread = pass(&mut decls, 1).create_texture(desc("unread", 64));
        pass(&mut decls, 2).write(target);
        // d writes nothing but reads back: a side effect keeps it.
        pass(&mut decls, 3).side_effect();
        let mut schedule = Schedule::default();
        schedule.compute(&decls, &NAMES).unwrap();
        assert_eq!(names(&schedule.order), ["c", "d"]);
        assert_eq!(names(&schedule.culled), ["a", "b"]);
        // Transients of culled passes get no memory.
        assert_eq!(schedule.slot_of[scratch.0.index as usize], None);
        assert_eq!(schedule.slot_of[unread.0.index as usize], None);
        assert!(schedule.slots.is_empty());
    }

    #[test]
    fn transients_share_memory_only_when_their_lifetimes_do_not_overlap() {
        let mut decls = Declarations::default();
        decls.begin(4);
        let target = imported(&mut decls, "target");
        let x = pass(&mut decls, 0).create_texture(desc("x", 64));
        pass(&mut decls, 1).read(x);
        let y = pass(&mut decls, 1).create_texture(desc("y", 64));
        // z has x's key and starts after x's last use: it reuses x's slot.
        let z = pass(&mut decls, 2).create_texture(desc("z", 64));
        pass(&mut decls, 2).read(y);
        // w has another size: its own slot whatever the lifetimes.
        let w = pass(&mut decls, 3).create_texture(desc("w", 32));
        let mut p = pass(&mut decls, 3);
        p.read(z);
        p.write(target);
        let mut schedule = Schedule::default();
        schedule.compute(&decls, &NAMES).unwrap();
        assert_eq!(names(&schedule.order), ["a", "b", "c", "d"]);
        let slot = |t: TextureId| schedule.slot_of[t.0.index as usize].unwrap();
        // x (a..b) and y (b..c) overlap; z (c..d) follows x.
        assert_ne!(slot(x), slot(y));
        assert_eq!(slot(z), slot(x));
        assert_ne!(slot(w), slot(x));
        assert_eq!(schedule.slots.len(), 3);
        // Slots of one key are numbered so the pool can hand out its n-th texture of a key.
        let mut ordinals: Vec<u32> = schedule
            .slots
            .iter()
            .filter(|(k, _)| *k == PoolKey::from(&desc("any", 64)))
            .map(|&(_, o)| o)
            .collect();
        ordinals.sort_unstable();
        assert_eq!(ordinals, [0, 1]);
    }

    #[test]
    fn cycles_and_stale_handles_are_errors() {
        let mut decls = Declarations::default();
        decls.begin(2);
        let x = imported(&mut decls, "x");
        let y = imported(&mut decls, "y");
        pass(&mut decls, 0).read(y);
        pass(&mut decls, 0).write(x);
        pass(&mut decls, 1).read(x);
        pass(&mut decls, 1).write(y);
        let mut schedule = Schedule::default();
        assert!(matches!(
            schedule.compute(&decls, &NAMES[..2]),
            Err(GraphError::Cycle(_))
        ));

        // A handle from the previous build names nothing in this one.
        decls.begin(2);
        pass(&mut decls, 1).read(x);
        assert_eq!(
            schedule.compute(&decls, &NAMES[..2]),
            Err(GraphError::StaleHandle { node: "b" })
        );
    }
}
