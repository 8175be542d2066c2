//! Static entities: [`Static`] marks an entity placed once, as engines mark scenery (Unreal's
//! mobility, Unity's static flag). Every per-frame change scan of the shadow systems (the flat
//! transform propagation [`ShadowPlugin`](crate::ecs::ShadowPlugin) adds, and the instance
//! sync) filters static entities out by archetype, so a still frame touches none of them; the
//! marker's hooks list the entity for the next sync instead, when it is inserted (spawned
//! static, or marked again after a change) and when it is removed (the entity moves from then
//! on).

use bevy_ecs::component::Component;
use bevy_ecs::entity::Entity;
use bevy_ecs::hierarchy::{ChildOf, Children};
use bevy_ecs::lifecycle::{HookContext, RemovedComponents};
use bevy_ecs::query::{Added, Changed, Or, Without};
use bevy_ecs::resource::Resource;
use bevy_ecs::system::{ParamSet, Query, Res};
use bevy_ecs::world::DeferredWorld;
use bevy_transform::components::{GlobalTransform, Transform};

/// Marks an entity whose transform, mesh, material and shadow flags stay as they were when
/// the marker was inserted: the shadow systems never scan it again. To change such an entity,
/// insert `Static` again after the change (it is synced once more), or remove it first (it is
/// scanned every frame from then on, like any moving entity). A flat static entity's
/// `GlobalTransform` is set from its `Transform` when the marker is inserted.
///
/// Skinned meshes may be static: their pose is synced on its own, every frame it changes.
#[derive(Component, Clone, Copy, Debug, Default, PartialEq, Eq)]
#[component(on_insert = static_inserted, on_discard = static_discarded)]
pub struct Static;

/// Entities whose [`Static`] marker was inserted or removed since the last instance sync
/// (which drains it).
#[derive(Resource, Debug, Default)]
pub struct StaticChanges {
    /// Entities marked static (or marked again) since the last sync.
    pub marked: Vec<Entity>,
    /// Entities whose marker was removed since the last sync (they may have moved meanwhile).
    pub released: Vec<Entity>,
}

/// `Static`'s insert hook: places a flat entity and lists it for the next instance sync.
fn static_inserted(mut world: DeferredWorld, context: HookContext) {
    let entity = context.entity;
    place_flat(&mut world, entity);
    if let Some(mut changes) = world.get_resource_mut::<StaticChanges>() {
        changes.marked.push(entity);
    }
}

/// `Static`'s removal (and replacement) hook: lists the entity, whose transform may have
/// changed while it was static.
fn static_discarded(mut world: DeferredWorld, context: HookContext) {
    if let Some(mut changes) = world.get_resource_mut::<StaticChanges>() {
        changes.released.push(context.entity);
    }
}

/// Sets a flat entity's (no parent, no children) `GlobalTransform` from its `Transform`.
fn place_flat(world: &mut DeferredWorld, entity: Entity) {
    if world.get::<ChildOf>(entity).is_some() || world.get::<Children>(entity).is_some() {
        return;
    }
    let Some(transform) = world.get::<Transform>(entity).copied() else {
        return;
    };
    if let Some(mut global) = world.get_mut::<GlobalTransform>(entity) {
        let placed = GlobalTransform::from(transform);
        if *global != placed {
            *global = placed;
        }
    }
}

/// The flat entities (no parent, no children) whose transform changed, static ones excluded.
type MovedFlat<'w, 's> = Query<
    'w,
    's,
    (&'static Transform, &'static mut GlobalTransform),
    (
        Or<(Changed<Transform>, Added<GlobalTransform>)>,
        Without<ChildOf>,
        Without<Children>,
        Without<Static>,
    ),
>;

/// Every flat entity's placement (for the few listed to place again).
type FlatPlacements<'w, 's> =
    Query<'w, 's, (&'static Transform, &'static mut GlobalTransform), (Without<ChildOf>, Without<Children>)>;

/// Propagates the transforms of flat entities (no parent, no children) as `bevy_transform`'s
/// `sync_simple_transforms` does, except that [`Static`] entities are filtered out by
/// archetype: a scene of static casters costs nothing here per frame. Entities whose marker
/// was removed, and entities that just lost their parent, are placed again.
pub fn sync_moving_transforms(
    mut queries: ParamSet<(MovedFlat, FlatPlacements)>,
    mut orphaned: RemovedComponents<ChildOf>,
    changes: Option<Res<StaticChanges>>,
) {
    for (transform, mut global) in &mut queries.p0() {
        *global = GlobalTransform::from(*transform);
    }
    let released = changes.iter().flat_map(|c| c.released.iter().copied());
    let mut all = queries.p1();
    let mut placed = all.iter_many_mut(orphaned.read().chain(released)).matched();
    while let Some((transform, mut global)) = placed.fetch_next() {
        let now = GlobalTransform::from(*transform);
        if *global != now {
            *global = now;
        }
    }
}
