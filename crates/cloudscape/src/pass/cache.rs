//! Bind groups kept while the views they bind stay the same.

/// Bind groups made once and remade only when the views they bind change (a resized target): no
/// bind group is created per frame. Holds two, so a pass that alternates between ping-pong
/// targets (temporal history) keeps both.
#[derive(Default)]
pub struct BindGroupCache {
    entries: Vec<(Vec<wgpu::TextureView>, wgpu::BindGroup)>,
}

/// Bind groups a [`BindGroupCache`] keeps.
const CACHED_GROUPS: usize = 2;

impl BindGroupCache {
    /// The bind group for `views`, made by `make` when no kept group binds them.
    pub fn get(
        &mut self,
        views: &[&wgpu::TextureView],
        make: impl FnOnce() -> wgpu::BindGroup,
    ) -> &wgpu::BindGroup {
        let same = |kept: &[wgpu::TextureView]| {
            kept.len() == views.len() && kept.iter().zip(views).all(|(a, b)| a == *b)
        };
        let index = match self.entries.iter().position(|(kept, _)| same(kept)) {
            Some(index) => index,
            None => {
                if self.entries.len() == CACHED_GROUPS {
                    self.entries.remove(0);
                }
                let kept = views.iter().map(|v| (*v).clone()).collect();
                self.entries.push((kept, make()));
                self.entries.len() - 1
            }
        };
        &self.entries[index].1
    }

    /// Forgets the groups (a buffer they bind was replaced).
    pub fn clear(&mut self) {
        self.entries.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::GpuContext;
    use crate::gpu::pipeline::{bind_group, bind_group_layout, float_texture, texture_2d};

    #[test]
    fn cached_bind_groups_are_made_once_per_set_of_views() {
        let ctx = GpuContext::for_tests();
        let format = wgpu::TextureFormat::Rgba16Float;
        let usage = wgpu::TextureUsages::TEXTURE_BINDING;
        let view = |label| {
            texture_2d(&ctx, label, glam::UVec2::ONE, format, usage)
                .create_view(&Default::default())
        };
        let (a, b, c) = (view("a"), view("b"), view("c"));
        let layout = bind_group_layout(
            &ctx.device,
            "cache test",
            &[float_texture(wgpu::TextureViewDimension::D2)],
        );
        let mut made = 0;
        let mut cache = BindGroupCache::default();
        for v in [&a, &b, &a, &b, &a, &c, &c] {
            cache.get(&[v], || {
                made += 1;
                bind_group(
                    &ctx.device,
                    &layout,
                    &[wgpu::BindingResource::TextureView(v)],
                )
            });
        }
        assert_eq!(made, 3, "ping-pong between a and b makes each once; c once");
    }
}
