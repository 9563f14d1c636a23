//! [`SunPassPlugin`]: direct sun per pixel with stencil shadow volumes, the
//! thesis' algorithm 1, as a render system in Bevy's `Core3d` schedule after
//! the opaque pass.
//!
//! Per frame and view, in one render pass on the view's HDR target:
//! 1. the main depth (no stencil in Bevy) is copied into the pass's own
//!    `Depth24PlusStencil8` target, stencil cleared;
//! 2. the volumes of every opaque surface are counted into the low 7 stencil
//!    bits (depth-fail: front faces decrement, back faces increment where the
//!    depth test fails, so a camera inside a volume is still right);
//! 3. for every light through a window (the sun through each pane facing it;
//!    later each panel lobe, as a fake sun): that window's volume toggles the
//!    top bit, the lit surfaces are drawn again where the stencil reads
//!    exactly "top bit set, no opaque volume" adding ρ/π · E · τ · cos θ,
//!    and the window's volume is drawn again to clear the bit;
//! 4. the windows' volumes are added to the count and the sun is added where
//!    nothing at all is in the way (the outside of the building).
//!
//! The main world prepares what to draw ([`SunPassFrame`]) when the scene,
//! the sun or the render mode change; the render world uploads it once per
//! change.
//!
//! The main world's geometry ([`SunPassFrame`]: volumes and lights per
//! direction) is the core crate's `heliodon_core::sun_pass`; this module is
//! the Bevy side: [`SunPassPlugin`] and its resources, and the render
//! system.
//!
//! Files, as `bevy_pbr`'s atmosphere: this one has the plugin and the
//! main world's hand-over; [`resources`] the pipelines, buffers and stencil
//! targets of the render world; [`node`] the render system.

mod node;
mod resources;

use std::sync::Arc;

use bevy::core_pipeline::Core3dSystems;
use bevy::core_pipeline::core_3d::{main_opaque_pass_3d, main_transparent_pass_3d};
use bevy::core_pipeline::schedule::Core3d;
use bevy::prelude::*;
use bevy::render::extract_component::{ExtractComponent, ExtractComponentPlugin};
use bevy::render::extract_resource::{ExtractResource, ExtractResourcePlugin};
use bevy::render::{Render, RenderApp, RenderStartup, RenderSystems};

pub use heliodon_core::sun_pass::{DirectionPass, SunLight, SunPassFrame, SunPassSurfaces};

pub struct SunPassPlugin;

/// Marks the cameras that get the sun pass (they need `Hdr`, `Msaa::Off`
/// and a sampleable depth texture; [`super::hybrid_camera`] sets them up).
#[derive(Component, Clone, Copy, Default, ExtractComponent)]
pub struct SunPassView;

#[derive(Resource, Clone, Default, ExtractResource)]
pub struct SunPassInput(pub Option<Arc<SunPassFrame>>);
impl Plugin for SunPassPlugin {
    fn build(&self, app: &mut App) {
        let mut shaders = app.world_mut().resource_mut::<Assets<Shader>>();
        let _ = shaders
            .insert(SUN_PASS_SHADER.id(), Shader::from_wgsl(include_str!("../../../shaders/sun_pass.wgsl"), "shaders/sun_pass.wgsl"));
        let _ = shaders
            .insert(DEPTH_COPY_SHADER.id(), Shader::from_wgsl(include_str!("../../../shaders/depth_copy.wgsl"), "shaders/depth_copy.wgsl"));
        app.init_resource::<SunPassInput>()
            .add_plugins((ExtractResourcePlugin::<SunPassInput>::default(), ExtractComponentPlugin::<SunPassView>::default()));
        let Some(render_app) = app.get_sub_app_mut(RenderApp) else { return };
        render_app
            .init_resource::<resources::SunPassBuffers>()
            .add_systems(RenderStartup, resources::init_pipelines)
            .add_systems(Render, (resources::upload_frame, resources::prepare_stencil_targets).in_set(RenderSystems::PrepareResources))
            .add_systems(
                Core3d,
                node::sun_pass.after(main_opaque_pass_3d).before(main_transparent_pass_3d).in_set(Core3dSystems::MainPass),
            );
    }
}

pub(super) const SUN_PASS_SHADER: Handle<Shader> = bevy::asset::uuid_handle!("6b1f2c3e-9a57-4d0e-8f3a-2c6d5e7f8a91");
pub(super) const DEPTH_COPY_SHADER: Handle<Shader> = bevy::asset::uuid_handle!("0d4e5f6a-7b8c-4d9e-a0b1-c2d3e4f5a6b7");
