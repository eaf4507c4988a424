//! Property tests of `CONFIG.TXT` parsing: any bytes give a working
//! configuration without panicking, and the lines written into the log
//! header read back as the same configuration.

use proptest::prelude::*;
use wobble_core::config::{Config, FAULT_CODES};
use wobble_core::wheel::WheelSpeed;

fn emitted(config: &Config) -> String {
    let mut text = String::new();
    config.write_lines(&mut text).expect("String grows");
    text
}

/// The lines of the default configuration.
fn default_lines() -> Vec<String> {
    emitted(&Config::default())
        .lines()
        .map(str::to_owned)
        .collect()
}

/// The keys, as the firmware writes them.
fn key_names() -> Vec<String> {
    default_lines()
        .iter()
        .filter_map(|l| l.split_once('=').map(|(k, _)| k.to_owned()))
        .collect()
}

/// A value that is sometimes valid for its key and sometimes not.
fn value() -> impl Strategy<Value = String> {
    prop_oneof![
        (0.0f32..20.0).prop_map(|v| v.to_string()),
        (0u32..2_000_000).prop_map(|v| v.to_string()),
        Just("true".to_owned()),
        Just("off".to_owned()),
        "[ -~]{0,12}",
    ]
}

/// Lines made of real keys with plausible values, some noise in between.
fn config_text() -> impl Strategy<Value = String> {
    let names = key_names();
    let line = prop_oneof![
        4 => (proptest::sample::select(names), value(), " ?#?[ -~]{0,6}")
            .prop_map(|(k, v, tail)| format!("{k}={v}{tail}")),
        1 => "[ -~]{0,30}",
    ];
    proptest::collection::vec(line, 0..40).prop_map(|lines| lines.join("\n"))
}

proptest! {
    #[test]
    fn arbitrary_bytes_never_panic_and_give_a_working_config(
        bytes in proptest::collection::vec(any::<u8>(), 0..2048)
    ) {
        let loaded = Config::parse(&bytes);
        prop_assert!(WheelSpeed::try_new(loaded.config.wheel).is_ok());
        prop_assert!(loaded.config.detector.cost().is_ok());
        let lines = bytes.split(|&b| b == b'\n').count();
        let faults: usize = (1..=FAULT_CODES as u8)
            .map(|code| usize::from(loaded.faults.count(code)))
            .sum();
        // At most one fault per line, plus one per rejected section.
        prop_assert!(faults <= lines + 2);
    }

    #[test]
    fn emitted_lines_read_back_as_the_same_config(text in config_text()) {
        let first = Config::parse(text.as_bytes()).config;
        let again = Config::parse(emitted(&first).as_bytes());
        prop_assert!(again.faults.is_empty(), "{:?}", again.faults);
        prop_assert_eq!(again.config, first);
    }

    #[test]
    fn a_valid_line_sets_exactly_its_key(
        index in 0..key_names().len(),
        scale in 1.0f32..1.2,
    ) {
        let defaults = default_lines();
        let (key, default_value) = defaults[index].split_once('=').unwrap();
        // Nudge numeric values upwards a little: most stay valid.
        let new_value = match default_value.parse::<f32>() {
            Ok(v) if default_value.contains('.') => (v * scale).to_string(),
            _ => default_value.to_owned(),
        };
        let loaded = Config::parse(format!("{key}={new_value}").as_bytes());
        let in_force = emitted(&loaded.config);
        let changed: Vec<String> = in_force
            .lines()
            .zip(&defaults)
            .filter(|(a, b)| a != b)
            .map(|(a, _)| a.to_owned())
            .collect();
        if loaded.faults.is_empty() {
            // The key itself changed (or kept its value); nothing else did.
            let allowed = |l: &String| l.starts_with(&format!("{key}="));
            prop_assert!(changed.iter().all(allowed), "{changed:?}");
            let expected = format!("{key}={new_value}");
            prop_assert!(in_force.lines().any(|l| l == expected), "{expected} not in force");
        } else {
            // Rejected: the whole section is back at its defaults.
            prop_assert!(changed.is_empty(), "{changed:?}");
        }
    }
}

proptest! {
    #[test]
    fn every_finite_float_value_reads_back_exactly(bits in any::<u32>()) {
        let v = f32::from_bits(bits);
        prop_assume!(v.is_finite());
        // The steering centre accepts any finite number.
        let loaded = Config::parse(format!("steering.center_counts={v:?}\n").as_bytes());
        prop_assert!(loaded.faults.is_empty(), "{:?}", loaded.faults);
        prop_assert_eq!(loaded.config.steering.center_counts.to_bits(), v.to_bits());
        let text = emitted(&loaded.config);
        let line = text.lines().find(|l| l.starts_with("steering.center_counts=")).unwrap();
        let written: f32 = line.split_once('=').unwrap().1.parse().unwrap();
        prop_assert_eq!(written.to_bits(), v.to_bits(), "{}", line);
        // As short as the standard library's shortest form, or shorter.
        let digits = |t: &str| {
            let mantissa = t.split('e').next().unwrap_or_default();
            let all: String = mantissa.chars().filter(char::is_ascii_digit).collect();
            all.trim_matches('0').len()
        };
        let ours = line.split_once('=').unwrap().1;
        prop_assert!(digits(ours) <= digits(&format!("{v:e}")), "{} vs {:e}", ours, v);
    }
}
