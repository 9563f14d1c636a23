//! Synthetic EPW years for the annual tests at Boston's station: one with
//! sun only on the 21st of March, June, September and December (06:00-20:00,
//! DNI rising through the day), every other hour dark, so that a year is
//! quick; one with every third day clear.

/// The file's text with its first `rows` hours (8,760 for a whole year).
pub fn boston_epw(rows: usize) -> String {
    boston_year(rows, |month, day, hour| {
        let lit = day == 21 && month % 3 == 0 && (6..=20).contains(&hour);
        if lit { (60.0 * (hour as f64 - 5.0), 40.0 + 10.0 * (hour % 4) as f64) } else { (0.0, 0.0) }
    })
}

/// A whole synthetic Boston year in which every third day is clear (direct
/// normal 600 W/m² from 07:00 to 19:00) and the others dull (only diffuse
/// light, too little for 300 lux deep in a room): thousands of sunny
/// hours over every season, and a DA300 that follows the sun's way in.
#[allow(dead_code)]
pub fn boston_clear_thirds_epw() -> String {
    boston_year(8760, |_, day, hour| {
        let daytime = (7..=19).contains(&hour);
        match (daytime, day % 3 == 0) {
            (false, _) => (0.0, 0.0),
            (true, true) => (600.0, 70.0),
            (true, false) => (0.0, 40.0),
        }
    })
}

/// A dark Boston year but for two hours of 13 May: hour 5 (04:30, the sun
/// 0.5° up), whose Perez sky gendaylit refuses (parameter b > 0), and noon.
#[allow(dead_code)]
pub fn boston_refused_dawn_epw() -> String {
    boston_year(8760, |month, day, hour| match (month, day, hour) {
        (5, 13, 5) => (260.0, 23.0),
        (5, 13, 13) => (600.0, 100.0),
        _ => (0.0, 0.0),
    })
}

/// `rows` hours of a Boston EPW whose (direct normal, diffuse horizontal)
/// irradiance each hour `(month, day, hour)` gives.
fn boston_year(rows: usize, irradiance: impl Fn(u32, u32, u32) -> (f64, f64)) -> String {
    let mut text = String::from("LOCATION,Boston Logan,MA,USA,TMY3,725090,42.37,-71.01,-5.0,6.0\n");
    for header in ["DESIGN CONDITIONS,0", "TYPICAL/EXTREME PERIODS,0", "GROUND TEMPERATURES,0", "HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0"] {
        text += header;
        text.push('\n');
    }
    text += "COMMENTS 1,synthetic\nCOMMENTS 2,\nDATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31\n";
    let mut index = 0;
    for month in 1..=12u32 {
        for day in 1..=heliodon_core::time::days_in_month(2025, month) {
            for hour in 1..=24u32 {
                if index == rows {
                    return text;
                }
                index += 1;
                let (dni, dhi) = irradiance(month, day, hour);
                text += &format!("2025,{month},{day},{hour},60,?9?9?9?9E0,10,5,70,101000,0,0,300,0,{dni},{dhi},0,0,0,0,0,0,0,0,0\n");
            }
        }
    }
    text
}
