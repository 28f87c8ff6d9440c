//! `.rrd` files read back in Rust with Rerun's own decoder (`re_log_encoding`) and chunk types
//! (`re_chunk`), independent of the code that wrote them: what the Python `rerun-sdk` reader of the
//! viewer kit reported (entities, row counts, one component's values over `sim_time`, blueprints),
//! and what `rerun rrd verify` checks (every Rerun component column against Rerun's reflection,
//! the footer's manifests), without anything outside the repository.

use arrow::array::{Array, AsArray};
use arrow::datatypes::{DataType, Float32Type, Float64Type, Int32Type, Int64Type, UInt8Type, UInt16Type, UInt32Type, UInt64Type};
use re_chunk::Chunk;
use re_log_types::LogMsg;
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// An entity's rows and components, as `rrd-query.sh` listed them.
#[derive(Default, Debug)]
pub struct EntityInfo {
    pub rows: usize,
    pub static_rows: usize,
    /// component (e.g. `Scalars:scalars`) → rows holding it
    pub components: BTreeMap<String, usize>,
}

pub struct Rrd {
    /// the data recording's chunks (blueprint chunks apart)
    pub chunks: Vec<Chunk>,
    /// how many blueprint stores the file holds
    pub blueprints: usize,
    /// the blueprints' chunks (the layout: views, their names and properties)
    pub blueprint_chunks: Vec<Chunk>,
    /// problems `rerun rrd verify` would report
    pub verify_errors: Vec<String>,
    /// Rerun component columns checked against Rerun's reflection
    pub verified_columns: usize,
}

impl Rrd {
    pub fn open(path: &Path) -> Self {
        let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let file_len = file.metadata().unwrap().len();
        let mut decoder = re_log_encoding::DecoderApp::decode_lazy(std::io::BufReader::new(file));
        let mut chunks = Vec::new();
        let mut blueprints = BTreeSet::new();
        let mut blueprint_chunks = Vec::new();
        let mut verify_errors = Vec::new();
        let mut recording_chunks = 0usize;
        let mut verified_columns = 0usize;
        let reflection = re_sdk_types::reflection::generate_reflection().expect("Rerun's reflection");
        for msg in decoder.by_ref() {
            let msg = msg.unwrap_or_else(|e| panic!("{}: not a readable .rrd: {e}", path.display()));
            let LogMsg::ArrowMsg(store, arrow_msg) = msg else { continue };
            match re_sorbet::ChunkBatch::try_from(&arrow_msg.batch) {
                Ok(batch) => {
                    for (descriptor, column) in batch.component_columns() {
                        match verify_column(&reflection, descriptor, column.as_ref()) {
                            Ok(true) => verified_columns += 1,
                            Ok(false) => {}
                            Err(e) => verify_errors.push(format!("{}: {}: {e}", batch.entity_path(), descriptor.component_descriptor())),
                        }
                    }
                }
                Err(e) => verify_errors.push(format!("unparsable chunk: {e}")),
            }
            if store.is_blueprint() {
                blueprints.insert(store.clone());
                blueprint_chunks.push(Chunk::from_arrow_msg(&arrow_msg).expect("a valid blueprint chunk"));
                continue;
            }
            recording_chunks += 1;
            chunks.push(Chunk::from_arrow_msg(&arrow_msg).expect("a valid chunk"));
        }
        // the footer: one manifest per store, whose chunk offsets lie inside the file
        match decoder.rrd_manifests() {
            Ok(manifests) if manifests.is_empty() => verify_errors.push("missing RRD footer / no RRD manifests".into()),
            Ok(manifests) => {
                let recording = manifests.iter().filter(|m| m.store_id.is_recording()).collect::<Vec<_>>();
                if recording.len() != 1 {
                    verify_errors.push(format!("{} manifests of the data recording", recording.len()));
                }
                for m in &manifests {
                    let (offsets, sizes) = (m.col_chunk_byte_offset().expect("offsets"), m.col_chunk_byte_size().expect("sizes"));
                    if offsets.zip(sizes).any(|(o, s)| o + s > file_len) {
                        verify_errors.push("a manifest points past the end of the file".into());
                    }
                }
                if let Some(m) = recording.first() {
                    let listed = m.col_chunk_byte_offset().expect("offsets").count();
                    if listed != recording_chunks {
                        verify_errors.push(format!("the manifest lists {listed} chunks, the file has {recording_chunks}"));
                    }
                }
            }
            Err(e) => verify_errors.push(format!("corrupt RRD manifest: {e}")),
        }
        Self { chunks, blueprints: blueprints.len(), blueprint_chunks, verify_errors, verified_columns }
    }

    /// The blueprint's views by their display name, each with its y axis range where the blueprint
    /// sets one (`ScalarAxis:range` at `/view/<id>/ScalarAxis`, as the viewer reads it); where a
    /// value was logged again at a later blueprint time, the latest.
    pub fn view_axis_ranges(&self) -> BTreeMap<String, Option<[f64; 2]>> {
        let latest = |entity: &str, component: &str| {
            self.blueprint_chunks
                .iter()
                .filter(|c| c.entity_path().to_string() == entity)
                .filter_map(|c| {
                    let time = c.timelines().iter().find(|(name, _)| name.as_str() == "blueprint").map_or(i64::MIN, |(_, t)| t.times_raw()[0]);
                    c.components().0.values().find(|col| col.descriptor.component.as_str() == component).filter(|col| !col.list_array.is_null(0)).map(|col| (time, col.list_array.value(0)))
                })
                .max_by_key(|(time, _)| *time)
                .map(|(_, value)| value)
        };
        let mut views = BTreeMap::new();
        for chunk in &self.blueprint_chunks {
            let entity = chunk.entity_path().to_string();
            let Some(id) = entity.strip_prefix("/view/").filter(|rest| !rest.contains('/')) else { continue };
            let Some(name) = latest(&entity, "ViewBlueprint:display_name") else { continue };
            let name = name.as_string::<i32>().value(0).to_string();
            let range = latest(&format!("/view/{id}/ScalarAxis"), "ScalarAxis:range").map(|r| {
                let v = numbers(r.as_ref());
                [v[0], v[1]]
            });
            views.insert(name, range);
        }
        views
    }

    pub fn entities(&self) -> BTreeMap<String, EntityInfo> {
        let mut out: BTreeMap<String, EntityInfo> = BTreeMap::new();
        for chunk in &self.chunks {
            let e = out.entry(chunk.entity_path().to_string()).or_default();
            e.rows += chunk.num_rows();
            if chunk.is_static() {
                e.static_rows += chunk.num_rows();
            }
            for column in chunk.components().0.values() {
                let filled = column.list_array.len() - column.list_array.null_count();
                *e.components.entry(column.descriptor.component.to_string()).or_default() += filled;
            }
        }
        out
    }

    /// One entity's component on the `sim_time` timeline, in time order: (time in s, the row's
    /// numbers, every instance's flattened). Static rows and rows without the component are left out.
    pub fn component(&self, entity: &str, component: &str) -> Vec<(f64, Vec<f64>)> {
        let mut rows = Vec::new();
        for chunk in self.chunks.iter().filter(|c| c.entity_path().to_string() == entity) {
            let Some(time) = chunk.timelines().iter().find(|(name, _)| name.as_str() == "sim_time").map(|(_, t)| t) else { continue };
            let Some(column) = chunk.components().0.values().find(|c| c.descriptor.component.as_str() == component) else { continue };
            for (k, &t) in time.times_raw().iter().enumerate() {
                if column.list_array.is_null(k) {
                    continue;
                }
                rows.push((t as f64 * 1e-9, numbers(column.list_array.value(k).as_ref())));
            }
        }
        rows.sort_by(|a, b| a.0.total_cmp(&b.0));
        rows
    }

    /// How many instances an entity's static `component` holds (a mesh's triangles, a batch's
    /// boxes), over its static rows.
    pub fn static_instances(&self, entity: &str, component: &str) -> usize {
        let mut count = 0;
        for chunk in self.chunks.iter().filter(|c| c.is_static() && c.entity_path().to_string() == entity) {
            if let Some(column) = chunk.components().0.values().find(|c| c.descriptor.component.as_str() == component) {
                count += (0..column.list_array.len()).filter(|&k| !column.list_array.is_null(k)).map(|k| column.list_array.value(k).len()).sum::<usize>();
            }
        }
        count
    }

    /// An entity's static `component`, every static row's numbers flattened (a box's half sizes, a
    /// transform's translation).
    pub fn static_numbers(&self, entity: &str, component: &str) -> Vec<f64> {
        let mut out = Vec::new();
        for chunk in self.chunks.iter().filter(|c| c.is_static() && c.entity_path().to_string() == entity) {
            if let Some(column) = chunk.components().0.values().find(|c| c.descriptor.component.as_str() == component) {
                for k in (0..column.list_array.len()).filter(|&k| !column.list_array.is_null(k)) {
                    out.extend(numbers(column.list_array.value(k).as_ref()));
                }
            }
        }
        out
    }

    /// The `Scalars:scalars` rows of an entity.
    pub fn series(&self, entity: &str) -> Vec<(f64, Vec<f64>)> {
        self.component(entity, "Scalars:scalars")
    }
}

/// Every number of an Arrow array, flattened (lists, fixed-size lists, structs), as f64.
fn numbers(array: &dyn Array) -> Vec<f64> {
    let mut out = Vec::new();
    push_numbers(array, &mut out);
    out
}

fn push_numbers(a: &dyn Array, out: &mut Vec<f64>) {
    macro_rules! prim {
        ($t:ty) => {
            out.extend(a.as_primitive::<$t>().iter().flatten().map(|x| x as f64))
        };
    }
    match a.data_type() {
        DataType::Float64 => prim!(Float64Type),
        DataType::Float32 => prim!(Float32Type),
        DataType::Int32 => prim!(Int32Type),
        DataType::Int64 => prim!(Int64Type),
        DataType::UInt8 => prim!(UInt8Type),
        DataType::UInt16 => prim!(UInt16Type),
        DataType::UInt32 => prim!(UInt32Type),
        DataType::UInt64 => prim!(UInt64Type),
        DataType::Boolean => out.extend(a.as_boolean().iter().flatten().map(|b| b as u8 as f64)),
        DataType::FixedSizeList(..) => push_numbers(a.as_fixed_size_list().values().as_ref(), out),
        DataType::List(_) => push_numbers(a.as_list::<i32>().values().as_ref(), out),
        DataType::Struct(_) => {
            for column in a.as_struct().columns() {
                push_numbers(column.as_ref(), out);
            }
        }
        _ => {}
    }
}

/// What `rerun rrd verify` checks of one component column: a known, current Rerun component type,
/// every cell valid for it, and the archetype field of the type the archetype declares.
/// `Ok(false)`: not a Rerun component, nothing to check.
fn verify_column(reflection: &re_sdk_types::reflection::Reflection, descriptor: &re_sorbet::ComponentColumnDescriptor, column: &dyn Array) -> Result<bool, String> {
    use re_sdk_types::reflection::ComponentDescriptorExt as _;
    let d = descriptor.component_descriptor();
    let Some(component_type) = d.component_type else { return Ok(false) };
    if !component_type.full_name().starts_with("rerun.") {
        return Ok(false);
    }
    let info = reflection.components.get(&component_type).ok_or("unknown component type")?;
    if info.deprecation_summary.is_some() {
        return Err("deprecated component".into());
    }
    let list = column.as_list_opt::<i32>().ok_or_else(|| format!("expected a list array, found {}", column.data_type()))?;
    for i in 0..column.len() {
        (info.verify_arrow_array)(list.value(i).as_ref()).map_err(|e| e.to_string())?;
    }
    if let Some(archetype) = d.archetype.filter(|a| a.full_name().starts_with("rerun.")) {
        let arch = reflection.archetypes.get(&archetype).ok_or("unknown archetype")?;
        let field = arch.field_by_name(d.archetype_field_name()).ok_or("not a field of its archetype")?;
        if field.component_type != component_type {
            return Err(format!("field has type {:?}, the column {component_type:?}", field.component_type));
        }
    }
    Ok(true)
}
