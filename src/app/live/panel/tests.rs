use super::*;
use ratatui::crossterm::event::KeyEventKind;

fn key(code: KeyCode) -> KeyEvent {
    KeyEvent::new(code, KeyModifiers::NONE)
}

fn panel() -> Panel {
    let p = crate::scenario::presets::load("jiang2017-dual-axis").expect("preset");
    Panel::new(&p.resolved, "test".into())
}

fn value_of(p: &Panel, label: &str) -> f64 {
    p.controls
        .iter()
        .find_map(|c| match c {
            Control::Slider { label: l, value, .. } if l == label => Some(*value),
            _ => None,
        })
        .expect("slider")
}

#[test]
fn the_panel_offers_what_a_teacher_turns_with_the_scenario_values() {
    let p = panel();
    // Jiang et al. 2017 Table 2 values from the preset.
    assert_eq!(value_of(&p, "outer swing half-angle"), 600.0);
    assert_eq!(value_of(&p, "inner swing half-angle"), 300.0);
    assert_eq!(value_of(&p, "inner non-orthogonality"), 20.0);
    assert_eq!(value_of(&p, "outer rotation rate"), 10.0);
    assert_eq!(value_of(&p, "speed (× real time)"), 1.0);
    assert_eq!(value_of(&p, "3D exaggeration"), 100.0);
    assert!(
        p.controls.iter().any(|c| matches!(c, Control::Toggle { label, value: true, .. } if label == "compensation"))
    );
}

#[test]
fn arrows_select_and_adjust_and_write_the_right_key() {
    let mut p = panel();
    assert_eq!(p.selected, 0); // outer swing half-angle, 600″, step 10″
    assert_eq!(
        p.handle(key(KeyCode::Right)),
        Action::Set(vec![(KeyPath::parse("turntable.axis[0].swing_half_angle_arcsec"), Scalar::Float(610.0))])
    );
    let shift_left = KeyEvent {
        code: KeyCode::Left,
        modifiers: KeyModifiers::SHIFT,
        kind: KeyEventKind::Press,
        state: ratatui::crossterm::event::KeyEventState::NONE,
    };
    assert_eq!(
        p.handle(shift_left),
        Action::Set(vec![(KeyPath::parse("turntable.axis[0].swing_half_angle_arcsec"), Scalar::Float(510.0))])
    );
    assert_eq!(
        p.handle(key(KeyCode::Char('r'))),
        Action::Set(vec![(KeyPath::parse("turntable.axis[0].swing_half_angle_arcsec"), Scalar::Float(600.0))])
    );
    assert_eq!(
        p.handle(key(KeyCode::Home)),
        Action::Set(vec![(KeyPath::parse("turntable.axis[0].swing_half_angle_arcsec"), Scalar::Float(0.0))])
    );
    // At the minimum, further presses write nothing.
    assert_eq!(p.handle(key(KeyCode::Left)), Action::None);
    // Down moves to the next control; Up from the top wraps to the last (the compensation toggle).
    p.handle(key(KeyCode::Down));
    assert_eq!(p.selected, 1);
    p.handle(key(KeyCode::Up));
    p.handle(key(KeyCode::Up));
    assert_eq!(p.selected, p.controls.len() - 1);
    assert_eq!(
        p.handle(key(KeyCode::Char(' '))),
        Action::Set(vec![(KeyPath::parse("compensation.enabled"), Scalar::Bool(false))])
    );
    assert_eq!(p.handle(key(KeyCode::Char('q'))), Action::Quit);
    assert_eq!(p.handle(KeyEvent::new(KeyCode::Char('c'), KeyModifiers::CONTROL)), Action::Quit);
}

#[test]
fn logarithmic_sliders_walk_the_1_2_5_ladder() {
    // The speed slider used to write 1.25^5 = 3.051758 into the file: now round values only.
    let mut p = panel();
    p.selected = p
        .controls
        .iter()
        .position(|c| matches!(c, Control::Slider { label, .. } if label.starts_with("speed")))
        .expect("speed");
    let speed = |v: f64| Action::Set(vec![(KeyPath::parse("live.speed"), Scalar::Float(v))]);
    for expected in [2.0, 5.0, 10.0, 20.0] {
        assert_eq!(p.handle(key(KeyCode::Right)), speed(expected));
    }
    assert_eq!(p.handle(key(KeyCode::Left)), speed(10.0));
    assert_eq!(p.handle(key(KeyCode::PageUp)), speed(100.0)); // coarse: a decade
    assert_eq!(p.handle(key(KeyCode::PageDown)), speed(10.0));
    // A value edited in by hand (3.05) steps to the next rung, 5, and back to 2.
    assert_eq!(super::ladder(3.05, 1.0), 5.0);
    assert_eq!(super::ladder(3.05, -1.0), 2.0);
    assert_eq!(super::ladder(0.1, -1.0), 0.05);
}

#[test]
fn esc_closes_the_help_and_does_not_end_the_session() {
    let mut p = panel();
    p.handle(key(KeyCode::Char('?')));
    assert!(p.show_help);
    assert_eq!(p.handle(key(KeyCode::Esc)), Action::None);
    assert!(!p.show_help);
    assert_eq!(p.handle(key(KeyCode::Esc)), Action::None);
}

#[test]
fn sync_follows_edits_made_elsewhere() {
    let mut p = panel();
    let mut raw = crate::scenario::presets::load("jiang2017-dual-axis").expect("preset").resolved;
    raw.turntable.axis[1].swing_half_angle_arcsec = 4000.0; // beyond the slider's range: the range grows
    p.sync(&raw);
    assert_eq!(value_of(&p, "inner swing half-angle"), 4000.0);
}

#[test]
fn renders_without_a_terminal() {
    let p = panel();
    let status = super::super::new_status(&crate::scenario::presets::load("jiang2017-dual-axis").expect("preset"), 1.0);
    let status = status.lock().expect("lock").clone();
    let mut term = ratatui::Terminal::new(ratatui::backend::TestBackend::new(110, 40)).expect("terminal");
    term.draw(|f| p.render(f, &status, "x.toml")).expect("draw");
    let text: String = term.backend().buffer().content().iter().map(ratatui::buffer::Cell::symbol).collect();
    assert!(text.contains("outer swing half-angle"));
    assert!(text.contains("600″"));
    assert!(text.contains("q quit"));
    assert!(text.contains("error since the last change"), "the current error is beside the sliders");
    assert!(text.contains("range 0 … 3600″, step 10″"), "the selected slider shows its range");
}
