//! The scene's knobs as widgets: one row per knob of the library's registry
//! (`cloudscape::scene::knobs`), with its unit, and its description and range on hover. Nothing
//! here restates a range, a unit or a description.

use cloudscape::scene::knobs::{self, Allowed, DocumentedFields, Field, FieldMut, Knob};
use cloudscape::scene::{Scene, TimeOfDay};

/// Keys the viewer sets itself every frame (the camera it flies, the viewport's size, its clock):
/// shown, not edited.
const VIEWER_OWNED: [&str; 7] = [
    "camera.position_m",
    "camera.look_at_m",
    "camera.yaw_deg",
    "camera.pitch_deg",
    "render.width",
    "render.height",
    "render.time_s",
];

/// The scene's sections in the order the panel shows them (`layers` after `render`).
const SECTIONS: [&str; 13] = [
    "render",
    "sun",
    "sky",
    "phase",
    "lighting",
    "noise",
    "weather",
    "camera",
    "shadow",
    "ground",
    "planet",
    "particles",
    "sprites",
];

/// Where a knob sits, to name it and to report an edit.
struct Place<'a> {
    /// The dotted key in the scene file.
    key: String,
    /// The name shown: the key within its section.
    label: &'a str,
}

/// Shows every knob of `scene` by section; returns the dotted key of the knob changed, if one was
/// (then `scene` holds the change). `resolved` gives the value an unset optional knob takes (a
/// quality preset's step count).
pub fn scene_sections(
    ui: &mut egui::Ui,
    scene: &mut Scene,
    resolved: &dyn Fn(&str, &Scene) -> Option<u32>,
) -> Option<String> {
    let mut changed = section(ui, "render", scene, resolved);
    changed = changed.or(layer_sections(ui, scene));
    for name in &SECTIONS[1..] {
        changed = changed.or(section(ui, name, scene, resolved));
    }
    changed
}

/// One top-level table of the scene as a collapsing section.
fn section(
    ui: &mut egui::Ui,
    name: &str,
    scene: &mut Scene,
    resolved: &dyn Fn(&str, &Scene) -> Option<u32>,
) -> Option<String> {
    let hover = Scene::get_field_docs(name).unwrap_or_default();
    let header = egui::CollapsingHeader::new(name).default_open(name == "render");
    let shown = header.show(ui, |ui| {
        let mut changed = None;
        if name == "sun" {
            changed = time_of_day(ui, scene);
        }
        let rows = knobs::SCENE
            .iter()
            .filter(|k| k.key.split('.').next() == Some(name));
        let skip = name.len() + 1;
        changed.or(knob_grid(ui, name, rows, ("", skip), scene, resolved))
    });
    shown.header_response.on_hover_text(hover);
    shown.body_returned.flatten()
}

/// The sun's place from a time of day: a switch, and its knobs when on.
fn time_of_day(ui: &mut egui::Ui, scene: &mut Scene) -> Option<String> {
    let mut on = scene.sun.time_of_day.is_some();
    let hover = cloudscape::scene::Sun::get_field_docs("time_of_day").unwrap_or_default();
    let mut changed = None;
    if ui
        .checkbox(&mut on, "from the time of day")
        .on_hover_text(hover)
        .changed()
    {
        scene.sun.time_of_day = on.then_some(STARTING_TIME_OF_DAY);
        changed = Some("sun.time_of_day".to_string());
    }
    if let Some(time) = scene.sun.time_of_day.as_mut() {
        let rows = knobs::TIME_OF_DAY.iter();
        let prefix = ("sun.time_of_day.", 0);
        changed = changed.or(knob_grid(ui, "time of day", rows, prefix, time, &|_, _| {
            None
        }));
    }
    changed
}

/// Where the time of day starts when it is switched on: a summer afternoon at mid-latitude
/// (15 h solar time, 48 deg N, 21 June).
const STARTING_TIME_OF_DAY: TimeOfDay = TimeOfDay {
    solar_time_h: 15.0,
    latitude_deg: 48.0,
    day_of_year: 172,
};

/// Each cloud layer as a collapsing section.
fn layer_sections(ui: &mut egui::Ui, scene: &mut Scene) -> Option<String> {
    let mut changed = None;
    let hover = Scene::get_field_docs("layers").unwrap_or_default();
    for (index, layer) in scene.layers.iter_mut().enumerate() {
        let header =
            egui::CollapsingHeader::new(format!("layers.{index}")).default_open(index == 0);
        let shown = header.show(ui, |ui| {
            let prefix = format!("layers.{index}.");
            let rows = knobs::LAYER.iter();
            knob_grid(ui, &prefix, rows, (&prefix, 0), layer, &|_, _| None)
        });
        shown.header_response.on_hover_text(hover);
        changed = changed.or(shown.body_returned.flatten());
    }
    changed
}

/// A grid of knob rows, one per knob of `knobs` in `item`: each named by its key with the first
/// `skip` characters left out, and reported by its key after `prefix`. `fallback` gives the value
/// an unset optional knob takes. Returns the full key of the knob changed, if one was.
fn knob_grid<'k, T: 'static>(
    ui: &mut egui::Ui,
    id: &str,
    knobs: impl Iterator<Item = &'k Knob<T>>,
    (prefix, skip): (&str, usize),
    item: &mut T,
    fallback: &dyn Fn(&str, &T) -> Option<u32>,
) -> Option<String> {
    let mut changed = None;
    grid(ui, id, |ui| {
        for knob in knobs {
            let place = Place {
                key: format!("{prefix}{}", knob.key),
                label: &knob.key[skip..],
            };
            let preset = fallback(&place.key, item);
            if row(ui, knob, &place, item, preset) {
                changed = Some(place.key);
            }
        }
    });
    changed
}

/// A grid of knob rows: name, widget, unit.
fn grid(ui: &mut egui::Ui, id: &str, rows: impl FnOnce(&mut egui::Ui)) {
    egui::Grid::new(id)
        .num_columns(3)
        .spacing([8.0, 3.0])
        .striped(true)
        .show(ui, rows);
}

/// One knob: its name (with its description, range and key on hover), its widget and its unit.
/// True when the user changed it.
fn row<T>(
    ui: &mut egui::Ui,
    knob: &Knob<T>,
    place: &Place,
    item: &mut T,
    fallback: Option<u32>,
) -> bool {
    let hover = format!(
        "{}\n\n{}: allowed {}",
        knob.description(),
        place.key,
        knob.allowed.describe(knob.unit)
    );
    ui.label(place.label).on_hover_text(hover);
    let changed = if VIEWER_OWNED.contains(&place.key.as_str()) {
        ui.label(shown(&knob.get(item)));
        false
    } else {
        widget(ui, knob.allowed, knob.get_mut(item), fallback)
    };
    ui.label(knob.unit);
    ui.end_row();
    changed
}

/// A value as text.
fn shown(field: &Field) -> String {
    match field {
        Field::Float(v) => format!("{v:.1}"),
        Field::Int(v) => v.to_string(),
        Field::Floats(values) => {
            let parts: Vec<String> = values.iter().map(|v| format!("{v:.0}")).collect();
            parts.join(", ")
        }
        Field::Bool(b) => b.to_string(),
        Field::Choice(choice) => choice.options()[choice.index()].0.clone(),
        Field::Absent => "-".to_string(),
    }
}

/// The widget for one value; true when changed.
fn widget(ui: &mut egui::Ui, allowed: Allowed, field: FieldMut, fallback: Option<u32>) -> bool {
    match field {
        FieldMut::Float(value) => number(ui, value, allowed),
        FieldMut::Int(value) => number(ui, value, allowed),
        FieldMut::Floats(values) => {
            ui.horizontal(|ui| {
                let mut changed = false;
                for value in values {
                    changed |= number(ui, value, allowed);
                }
                changed
            })
            .inner
        }
        FieldMut::Bool(value) => ui.checkbox(value, "").changed(),
        FieldMut::Choice(choice) => {
            let options = choice.options();
            let mut index = choice.index();
            egui::ComboBox::from_id_salt(ui.next_auto_id())
                .selected_text(options[index].0.as_str())
                .show_index(ui, &mut index, options.len(), |i| options[i].0.as_str())
                .changed()
                .then(|| choice.select(index))
                .is_some()
        }
        FieldMut::OptionalInt(value) => optional_int(ui, value, allowed, fallback),
        FieldMut::Unset => {
            ui.label("unset");
            false
        }
    }
}

/// A whole number that may be unset (a preset's value applies): a switch and the number.
fn optional_int(
    ui: &mut egui::Ui,
    value: &mut Option<u32>,
    allowed: Allowed,
    fallback: Option<u32>,
) -> bool {
    ui.horizontal(|ui| {
        let mut set = value.is_some();
        let mut changed = ui
            .checkbox(&mut set, "")
            .on_hover_text("set (else the preset's)")
            .changed();
        if changed {
            *value = set.then(|| fallback.unwrap_or(1));
        }
        match value {
            Some(v) => changed |= number(ui, v, allowed),
            None => {
                let preset = fallback.map_or("preset".to_string(), |v| format!("{v} (preset)"));
                ui.weak(preset);
            }
        }
        changed
    })
    .inner
}

/// A number within `allowed`: a slider when bounded on both sides, else a drag value.
fn number<N: egui::emath::Numeric>(ui: &mut egui::Ui, value: &mut N, allowed: Allowed) -> bool {
    let response = match allowed.bounds() {
        (Some(min), Some(max)) => {
            let log = min > 0.0 && max / min >= 1000.0;
            let slider =
                egui::Slider::new(value, N::from_f64(min.into())..=N::from_f64(max.into()))
                    .logarithmic(log);
            ui.add(slider)
        }
        (min, _) => {
            let speed = (value.to_f64().abs() * 0.01).max(0.01);
            let min = min.map_or(f64::NEG_INFINITY, f64::from);
            let drag = egui::DragValue::new(value)
                .speed(speed)
                .range(N::from_f64(min)..=N::from_f64(f64::INFINITY));
            ui.add(drag)
        }
    };
    response.changed()
}
