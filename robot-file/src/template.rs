//! A new robot's files (`pada new-robot NAME`): a URDF of one arm on one
//! servo and a `robot.toml` that learns to hold it level against gravity,
//! every field commented. They run as they are (`pada run --robot
//! NAME/robot.toml`); change them into your robot's.

/// The `robot.toml` of a new robot called `name` whose URDF is
/// `NAME.urdf` beside it.
pub fn robot_toml(name: &str) -> String {
    format!(
        r#"# {name}: a robot of your own for pada. Every field is described once in
# pada's docs/your-robot.md; units are in the field names.
#
#   pada run --robot {name}/robot.toml --algo pada          # learn on the host
#   pada run --robot {name}/robot.toml --algo pada --board f405   # as the board would
#   cargo xtask firmware --release --board f405 --robot {name}/robot.toml

[robot]
name = "{name}"           # lowercase letters, digits and '-', at most 32
urdf = "{name}.urdf"      # the body, relative to this file
period_ms = 30            # the control period
episode_s = 5             # each episode's length (a time limit)
test_interval = 10        # a greedy test episode after every N learning episodes
supply_v = 12.0           # the servos' supply, assumed until they report it
voltage_limit_v = 12.0    # every voltage sent is clipped to +-this

# One [[joint]] per moving joint of the URDF, in the robot's joint order.
[[joint]]
urdf = "shoulder"         # the URDF joint (revolute or continuous)
servo = "XM430-W350"      # RX-28, MX-28, XM430-W350, XL430-W250 or XL330-M288
id = 1                    # its bus ID
zero_count = 2048         # its position count at joint angle 0
sign = 1                  # 1 if the angle grows with the count, -1 if not
soft_limit_rad = [-2.5, 2.5]   # past these the robot faults, torque off
start_rad = 0.0           # its angle in the start pose
# learned = true          # the learner drives it (default); false: held by
# hold_gain_v_per_rad = 5 #   a P law with this gain towards hold_target_rad
# counted = true          # its gear wear counts in the MTBF (default: if learned)

# Points of links that rewards and observations name.
[point.tip]
link = "arm"              # the URDF link
offset_m = [0.0, 0.0, 0.12]   # where on it, in the link's frame

# The observation: one [[observe]] per dimension. Signals: JOINT.angle,
# JOINT.rate, POINT.x|y|z, POINT.x_rate|y_rate|z_rate.
[[observe]]
signal = "shoulder.angle"
range = [-2.0, 2.0]       # the tile coder's range (values outside clamp)
tile = 0.2                # the width of one tile

[[observe]]
signal = "shoulder.rate"
range = [-6.0, 6.0]
tile = 2.0

# The voltage levels of each learned joint (or uniform_v = {{ min, max, count }}).
[action]
levels_v = [-3.0, 0.0, 3.0]
# tile_v = 3.0            # generalise over neighbouring levels

# SARSA(lambda); Section VII's values when left out.
[learning]
alpha = 0.2
gamma = 0.97
lambda = 0.9
epsilon = 0.05
initial_weights = [0.0, 0.0]   # uniform in [min, max]; optimistic when >= every return

# The reward: a sum of terms (quadratic, distance, progress, action,
# action_change, constant). Here: hold the arm level (a quarter turn).
[[reward]]
term = "quadratic"
signal = "shoulder.angle"
target = 1.5708
weight = -1.0

[[reward]]
term = "action"           # -0.01 per V squared
weight = -0.01

# Limits that end an episode, with their reward (optional). Here the arm's
# fall ends it well inside the soft limits: past those the robot faults and
# waits for you, while an end lets the reset bring it back by itself.
[[end]]
signal = "shoulder.angle"
range = [-1.9, 1.9]
reward = -10.0

# Between episodes on the robot: every joint held towards the start pose.
[reset]
gain_v_per_rad = 4.0
tolerance_rad = 0.05
still_rad_s = 0.2
settle_s = 0.5
timeout_s = 8.0

# How the host simulates the body (rapier3d).
[simulation]
substeps = 1              # physics steps per control period
solver_iterations = 2     # rapier's solver iterations per physics step
"#
    )
}

/// The URDF of a new robot called `name`: one XM430-W350 on a fixed base
/// turning a 12 cm arm about y.
pub fn urdf(name: &str) -> String {
    format!(
        r#"<?xml version="1.0"?>
<!-- {name}: one servo turning an arm in a vertical plane (z up). Replace
     it with your robot's body: a tree of links with a fixed root; every
     moving joint revolute or continuous, with a servo in robot.toml. -->
<robot name="{name}">
  <!-- The fixed base (the URDF's root link). -->
  <link name="base"/>

  <!-- The servo's horn, 46 mm above the base; the arm turns about y. Its
       limits are the mechanical stops: robot.toml's soft limits lie within
       them. -->
  <joint name="shoulder" type="revolute">
    <parent link="base"/>
    <child link="arm"/>
    <origin xyz="0 0 0.046" rpy="0 0 0"/>
    <axis xyz="0 1 0"/>
    <limit lower="-2.6" upper="2.6" effort="4.1" velocity="4.8"/>
  </joint>

  <!-- A 12 cm arm of 40 g, its centre of mass 6 cm out. -->
  <link name="arm">
    <inertial>
      <origin xyz="0 0 0.06"/>
      <mass value="0.04"/>
      <inertia ixx="4.8e-5" ixy="0" ixz="0" iyy="4.8e-5" iyz="0" izz="2e-6"/>
    </inertial>
  </link>
</robot>
"#
    )
}
