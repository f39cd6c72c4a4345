use cloudscape::field::CloudField;
use cloudscape::scene::SceneDocument;
use glam::Vec3;
fn main() {
    let overrides: Vec<String> = std::env::args().skip(1).collect();
    let doc = SceneDocument::load(None, &overrides).unwrap();
    let field = CloudField::new(&doc.scene, &doc.resolve_path("")).unwrap();
    let step = 250.0;
    let n = 120; // 30 km square
    let mut grid = vec![0f32; n * n];
    for i in 0..n {
        for j in 0..n {
            let x = (i as f32 - n as f32 / 2.0) * step;
            let z = (j as f32 - n as f32 / 2.0) * step;
            let mut tau = 0.0;
            for k in 0..20 {
                let y = 1500.0 + 110.0 * k as f32 + 55.0;
                tau += field.extinction_per_m(Vec3::new(x, y, z), 0.0) * 110.0;
            }
            grid[i * n + j] = tau;
        }
    }
    for j in 0..n {
        let row: String = (0..n)
            .map(|i| {
                let t = grid[i * n + j];
                if t > 5.0 {
                    '#'
                } else if t > 0.5 {
                    '+'
                } else {
                    '.'
                }
            })
            .collect();
        println!("{row}");
    }
}
