//! The layout a `.rrd` opens to (a Rerun blueprint) and the plots' colours in Rerun's type.

use super::TIMELINE;
use crate::recorder::shared::plot_colours::joint_rgb;
use crate::recorder::shared::torque_axis::TorqueAxis;
use rerun::RecordingStream;
use rerun::blueprint::components::{PanelState, PlayState};
use rerun::blueprint::{Blueprint, BlueprintActivation, BlueprintPanel, ContainerLike, Grid, Horizontal, SelectionPanel, Spatial3DView, TimePanel, TimeSeriesView, Vertical};

pub(super) fn rgb((r, g, b): (u8, u8, u8)) -> rerun::Color {
    rerun::Color::from_rgb(r, g, b)
}

pub fn joint_color(j: usize) -> rerun::Color {
    rgb(joint_rgb(j))
}

/// The layout the file opens to: the arm in 3D with the tool's position below it, and per joint
/// its angle against the target and its torque against the motor's limits, saturated steps marked.
/// With steppers driven open loop (`stepped`), a third row: each one's load angle and lost steps.
/// Each torque view's y range is `torque_axes`' (the motion's own torque, the limit beside it where
/// near; [`TorqueAxis`]): returned beside the blueprint as (view, half range), for [`send_blueprint`].
pub fn blueprint(joint_names: &[String], stepped: &[bool], servo_driven: &[bool], heated: &[bool], collisions: bool, torque_axes: &[TorqueAxis], prefix: &str) -> (Blueprint, Vec<(rerun::EntityPath, f64)>) {
    let angle_views = joint_names.iter().map(|j| {
        TimeSeriesView::new(format!("{j} angle vs target"))
            .with_origin(format!("{prefix}joints/{j}"))
            .with_contents(["$origin/position", "$origin/observed"])
            .into()
    });
    let mut torque_ranges = Vec::new();
    let torque_views: Vec<ContainerLike> = joint_names
        .iter()
        .enumerate()
        .map(|(i, j)| {
            let axis = torque_axes.get(i);
            let view: ContainerLike = TimeSeriesView::new(axis.map_or_else(|| format!("{j} torque vs ±limit"), |a| a.title(j)))
                .with_origin(format!("{prefix}joints/{j}"))
                .with_contents(["$origin/torque", "$origin/torque_limit", "$origin/saturated_torque", "$origin/friction", "$origin/measured_effort"])
                .into();
            if let (Some(axis), ContainerLike::View(v)) = (axis, &view) {
                torque_ranges.push((v.blueprint_path(), axis.half_range));
            }
            view
        })
        .collect();
    let columns = joint_names.len().div_ceil(2).clamp(1, 4) as u32;
    let mut left_views: Vec<ContainerLike> = vec![
        Spatial3DView::new("arm").with_origin(format!("{prefix}world")).into(),
        TimeSeriesView::new("tool position").with_origin(format!("{prefix}tool")).into(),
        TimeSeriesView::new("tool tip error").with_origin(format!("{prefix}tool_error")).into(),
    ];
    let mut left_shares = vec![4.0, 1.0, 1.0];
    let windings: Vec<String> = joint_names.iter().zip(heated).filter(|(_, h)| **h).map(|(j, _)| format!("/{prefix}joints/{j}/winding_temperature")).collect();
    if !windings.is_empty() {
        left_views.push(TimeSeriesView::new("motor winding temperature (°C)").with_origin(format!("/{prefix}joints")).with_contents(windings).into());
        left_shares.push(1.0);
    }
    if collisions {
        left_views.push(
            Horizontal::new([
                TimeSeriesView::new("pairs in contact").with_origin(format!("{prefix}collisions/in_contact")).into(),
                TimeSeriesView::new("closest pair within 5 cm (m)").with_origin(format!("{prefix}collisions/min_distance")).into(),
                rerun::blueprint::TextLogView::new("contacts").with_origin(format!("{prefix}collisions/events")).into(),
            ])
            .into(),
        );
        left_shares.push(1.2);
    }
    let left = Vertical::new(left_views).with_row_shares(left_shares);
    let stepper_views: Vec<_> = joint_names
        .iter()
        .zip(stepped.iter().chain(std::iter::repeat(&false)))
        .filter(|(_, s)| **s)
        .map(|(j, _)| TimeSeriesView::new(format!("{j} stepper: load angle, lost steps, motor rev/s")).with_origin(format!("{prefix}joints/{j}")).with_contents(["$origin/load_angle", "$origin/lost_steps", "$origin/motor_speed"]).into())
        .collect();
    let servo_views: Vec<_> = joint_names
        .iter()
        .zip(servo_driven.iter().chain(std::iter::repeat(&false)))
        .filter(|(_, s)| **s)
        .map(|(j, _)| TimeSeriesView::new(format!("{j} servo: PWM duty, current (A)")).with_origin(format!("{prefix}joints/{j}")).with_contents(["$origin/servo"]).into())
        .collect();
    let mut rows = vec![
        Grid::new(angle_views).with_grid_columns(columns).with_name("joint angles").into(),
        Grid::new(torque_views).with_grid_columns(columns).with_name("joint torques").into(),
    ];
    if !stepper_views.is_empty() {
        rows.push(Grid::new(stepper_views).with_grid_columns(columns).with_name("steppers").into());
    }
    if !servo_views.is_empty() {
        rows.push(Grid::new(servo_views).with_grid_columns(columns).with_name("servos").into());
    }
    let right = Vertical::new(rows);
    let blueprint = Blueprint::new(Horizontal::new([left.into(), right.into()]).with_column_shares([2.0, 3.0]))
        .with_time_panel(TimePanel::new().with_timeline(TIMELINE).with_play_state(PlayState::Following).with_state(PanelState::Collapsed))
        .with_selection_panel(SelectionPanel::new().with_state(PanelState::Collapsed))
        .with_blueprint_panel(BlueprintPanel::new().with_state(PanelState::Collapsed));
    (blueprint, torque_ranges)
}

/// Send `blueprint` to `rec` with each listed view's y axis set to ±half range (a `ScalarAxis`
/// property; the user can still zoom). rerun 0.36's Rust builder keeps view properties
/// crate-private (only the graph and map views expose theirs), so the blueprint is built into
/// memory and the axis properties are logged into the same blueprint store, at the views' own
/// paths (`view/<id>/ScalarAxis`, as the Python SDK writes them), before its activation (the
/// viewer copies a blueprint when it activates it: later messages would not reach the copy).
pub fn send_blueprint(rec: &RecordingStream, blueprint: &Blueprint, axis_ranges: &[(rerun::EntityPath, f64)]) -> rerun::RecordingStreamResult<()> {
    use rerun::external::re_log_types::LogMsg;
    let activation = BlueprintActivation { make_active: true, make_default: true };
    if axis_ranges.is_empty() {
        return blueprint.send(rec, activation);
    }
    let application = rec.store_info().map(|info| info.application_id().clone()).unwrap_or_else(|| rerun::ApplicationId::from("armscope"));
    let (staging, staged) = rerun::RecordingStreamBuilder::new(application).memory()?;
    blueprint.send(&staging, activation)?;
    let mut messages = staged.take();
    let Some(command) = messages.iter().find_map(|m| match m {
        LogMsg::BlueprintActivationCommand(c) => Some(c.clone()),
        _ => None,
    }) else {
        return blueprint.send(rec, activation);
    };
    let store = command.blueprint_id.clone();
    messages.retain(|m| !matches!(m, LogMsg::BlueprintActivationCommand(_)) && *m.store_id() == store);
    messages.extend(axis_messages(&store, axis_ranges)?);
    rec.send_blueprint(messages, command);
    Ok(())
}

/// The blueprint store's messages setting each view's `ScalarAxis` range.
fn axis_messages(store: &rerun::StoreId, axis_ranges: &[(rerun::EntityPath, f64)]) -> rerun::RecordingStreamResult<Vec<rerun::external::re_log_types::LogMsg>> {
    use rerun::external::re_log_types::LogMsg;
    use rerun::external::re_sdk_types::blueprint::archetypes::ScalarAxis;
    let (axes, staged) = rerun::RecordingStreamBuilder::new(store.application_id().clone()).recording_id(store.recording_id().clone()).blueprint().memory()?;
    axes.set_time_sequence("blueprint", 0);
    for (view, half_range) in axis_ranges {
        axes.log(format!("{view}/ScalarAxis"), &ScalarAxis::new().with_range(rerun::components::Range1D(rerun::datatypes::Range1D([-half_range, *half_range]))))?;
    }
    Ok(staged.take().into_iter().filter(|m| matches!(m, LogMsg::ArrowMsg(..)) && m.store_id() == store).collect())
}
