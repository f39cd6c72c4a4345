//! The parser: the report split into groups, each read in the order FM 15 gives them
//! (WMO-No. 306, FM 15 regulations 15.1-15.13).

use super::{
    Bound, ClearSky, CloudGroup, Convective, Cover, Descriptor, Intensity, MetarError,
    ObservationTime, Phenomenon, Report, ReportKind, SkyGroup, Visibility, WeatherGroup, Wind,
};

/// Metres per second in one knot (1852 m per hour).
const M_PER_S_PER_KNOT: f32 = 0.514444;
/// Metres in one statute mile.
const METRES_PER_MILE: f32 = 1609.344;
/// Hectopascals in one inch of mercury.
const HPA_PER_INCH_HG: f32 = 33.8639;
/// Groups that start the trend forecast or the remarks, where this parser stops.
const END_GROUPS: [&str; 4] = ["NOSIG", "BECMG", "TEMPO", "RMK"];

/// Reads `text` as a METAR or SPECI report; an unreadable group is an error naming it and its
/// column.
pub fn parse(text: &str) -> Result<Report, MetarError> {
    let groups = split(text);
    let mut cursor = Cursor {
        groups: &groups,
        next: 0,
        after: "the start of the report",
    };
    if groups.is_empty() {
        return Err(MetarError {
            group: String::new(),
            column: 1,
            offset: 0,
            message: "the report is empty; expected e.g. \"EGLL 011750Z 24012KT 9999 SCT030 18/12 Q1012\""
                .to_string(),
        });
    }
    let kind = cursor
        .take("report type", report_kind)
        .unwrap_or(ReportKind::Metar);
    let mut corrected = cursor.take("COR", |g| (g == "COR").then_some(())).is_some();
    let station = cursor.require(
        "station",
        station,
        "the station's four-letter ICAO location indicator, e.g. EGLL",
    )?;
    let time = cursor.require(
        "observation time",
        observation_time,
        "the day and time of the observation, ddhhmmZ, e.g. 011750Z",
    )?;
    let mut automatic = false;
    while let Some(modifier) = cursor.take("modifier", modifier) {
        match modifier {
            Modifier::Auto => automatic = true,
            Modifier::Correction => corrected = true,
            Modifier::Nil => {
                return Err(cursor.error_at(
                    cursor.next - 1,
                    "the report is NIL: the station sent no observation".to_string(),
                ));
            }
        }
    }
    let mut wind = cursor.take("wind", wind).flatten();
    if let Some(varying) = cursor.take("wind variation", wind_variation) {
        if let Some(wind) = &mut wind {
            wind.varying_deg = Some(varying);
        }
    }
    let mut cavok = false;
    let visibility = cursor.take("visibility", |g| {
        if g == "CAVOK" {
            cavok = true;
            Some(ten_km_or_more())
        } else {
            visibility(g)
        }
    });
    cursor.take("lowest visibility", directional_visibility);
    while cursor
        .take("runway visual range", runway_visual_range)
        .is_some()
    {}
    let weather = cursor.take_all("present weather", present_weather);
    let sky = cursor.take_all("cloud", sky_group);
    let temperatures = cursor.take("temperature", temperatures);
    let pressures = cursor.take_all("pressure", pressure);
    while cursor.take("recent weather", recent_weather).is_some() {}
    cursor.finish()?;
    let (temperature_c, dew_point_c) = temperatures.unwrap_or((None, None));
    Ok(Report {
        kind,
        station,
        time,
        corrected,
        automatic,
        wind,
        visibility,
        cavok,
        weather,
        sky,
        temperature_c,
        dew_point_c,
        qnh_hpa: pressures.into_iter().flatten().next(),
    })
}

/// One group of the report and where it starts.
#[derive(Clone, Debug)]
struct Group<'a> {
    text: &'a str,
    /// Byte offset in the report.
    offset: usize,
    /// 1-based column in characters.
    column: usize,
}

/// Splits the report at white space; a closing `=` is dropped, and a whole number of statute
/// miles followed by a fraction (`1 1/2SM`) is one group.
fn split(text: &str) -> Vec<Group<'_>> {
    let mut groups: Vec<Group<'_>> = Vec::new();
    let mut start = None;
    for (offset, c) in text.char_indices().chain([(text.len(), ' ')]) {
        match (c.is_whitespace(), start) {
            (false, None) => start = Some(offset),
            (true, Some(begin)) => {
                groups.push(Group {
                    text: &text[begin..offset],
                    offset: begin,
                    column: text[..begin].chars().count() + 1,
                });
                start = None;
            }
            _ => {}
        }
    }
    if let Some(last) = groups.last_mut() {
        last.text = last.text.strip_suffix('=').unwrap_or(last.text);
        if last.text.is_empty() {
            groups.pop();
        }
    }
    let mut merged: Vec<Group<'_>> = Vec::with_capacity(groups.len());
    for group in groups {
        let whole_miles = merged.last().filter(|previous| {
            previous.text.len() == 1
                && previous.text.as_bytes()[0].is_ascii_digit()
                && group.text.ends_with("SM")
                && group.text.contains('/')
        });
        match whole_miles {
            Some(previous) => {
                let start = previous.offset;
                let column = previous.column;
                merged.pop();
                merged.push(Group {
                    text: &text[start..group.offset + group.text.len()],
                    offset: start,
                    column,
                });
            }
            None => merged.push(group),
        }
    }
    merged
}

/// Walks the groups in order.
struct Cursor<'g, 'a> {
    groups: &'g [Group<'a>],
    next: usize,
    /// Name of the last group read, for messages.
    after: &'static str,
}

impl Cursor<'_, '_> {
    /// The next group, unless the report has ended (at its end or at a trend or remark).
    fn peek(&self) -> Option<&str> {
        self.groups
            .get(self.next)
            .map(|g| g.text)
            .filter(|text| !END_GROUPS.contains(text))
    }

    /// Reads the next group with `read` when it is one (`name` names it in later messages).
    fn take<T>(
        &mut self,
        name: &'static str,
        mut read: impl FnMut(&str) -> Option<T>,
    ) -> Option<T> {
        let value = read(self.peek()?)?;
        self.next += 1;
        self.after = name;
        Some(value)
    }

    /// Reads as many groups of one kind as follow.
    fn take_all<T>(&mut self, name: &'static str, read: impl Fn(&str) -> Option<T>) -> Vec<T> {
        std::iter::from_fn(|| self.take(name, &read)).collect()
    }

    /// Reads a group that must be there; else an error saying what was `expected`.
    fn require<T>(
        &mut self,
        name: &'static str,
        read: impl FnMut(&str) -> Option<T>,
        expected: &str,
    ) -> Result<T, MetarError> {
        if let Some(value) = self.take(name, read) {
            return Ok(value);
        }
        Err(match self.groups.get(self.next) {
            Some(_) => self.error_at(self.next, format!("expected {expected}")),
            None => {
                let last = self.groups.len() - 1;
                self.error_at(
                    last,
                    format!("the report ends here; expected {expected} next"),
                )
            }
        })
    }

    /// Succeeds when every group has been read; else names the first one left.
    fn finish(&self) -> Result<(), MetarError> {
        let Some(text) = self.peek() else {
            return Ok(());
        };
        let message = match GROUP_KINDS.iter().find(|(_, is)| is(text)) {
            Some((kind, _)) => format!(
                "a {kind} group out of place: FM 15 puts it before the {} group",
                self.after
            ),
            None => format!(
                "not a METAR group that can follow the {} group (in FM 15 order: wind, \
                 visibility, runway visual range, weather, cloud, temperature, pressure, then \
                 NOSIG, BECMG, TEMPO or RMK)",
                self.after
            ),
        };
        Err(self.error_at(self.next, message))
    }

    fn error_at(&self, index: usize, message: String) -> MetarError {
        let group = &self.groups[index];
        MetarError {
            group: group.text.to_string(),
            column: group.column,
            offset: group.offset,
            message,
        }
    }
}

/// Whether a group is of one kind.
type Recognizer = fn(&str) -> bool;
/// Every kind of group after the observation time, by name, for telling a group out of place
/// from one that is not a group at all.
const GROUP_KINDS: [(&str, Recognizer); 9] = [
    ("wind", |g| wind(g).is_some()),
    ("wind variation", |g| wind_variation(g).is_some()),
    ("visibility", |g| g == "CAVOK" || visibility(g).is_some()),
    ("runway visual range", |g| runway_visual_range(g).is_some()),
    ("present weather", |g| present_weather(g).is_some()),
    ("cloud", |g| sky_group(g).is_some()),
    ("temperature", |g| temperatures(g).is_some()),
    ("pressure", |g| pressure(g).is_some()),
    ("modifier", |g| modifier(g).is_some()),
];

fn report_kind(group: &str) -> Option<ReportKind> {
    match group {
        "METAR" => Some(ReportKind::Metar),
        "SPECI" => Some(ReportKind::Speci),
        _ => None,
    }
}

/// ICAO location indicator: a letter and three letters or digits.
fn station(group: &str) -> Option<String> {
    let bytes = group.as_bytes();
    let valid = bytes.len() == 4
        && bytes[0].is_ascii_uppercase()
        && bytes[1..]
            .iter()
            .all(|b| b.is_ascii_uppercase() || b.is_ascii_digit());
    valid.then(|| group.to_string())
}

/// `n` ASCII digits as a number; `None` unless `text` is exactly that.
fn digits(text: &str, n: usize) -> Option<u32> {
    (text.len() == n && text.bytes().all(|b| b.is_ascii_digit()))
        .then(|| text.parse().ok())
        .flatten()
}

/// `YYGGggZ`.
fn observation_time(group: &str) -> Option<ObservationTime> {
    let body = group.strip_suffix('Z')?;
    digits(body, 6)?;
    let time = ObservationTime {
        day: digits(&body[0..2], 2)?,
        hour: digits(&body[2..4], 2)?,
        minute: digits(&body[4..6], 2)?,
    };
    ((1..=31).contains(&time.day) && time.hour < 24 && time.minute < 60).then_some(time)
}

enum Modifier {
    Auto,
    Correction,
    Nil,
}

fn modifier(group: &str) -> Option<Modifier> {
    match group {
        "AUTO" => Some(Modifier::Auto),
        "COR" => Some(Modifier::Correction),
        "NIL" => Some(Modifier::Nil),
        _ => None,
    }
}

/// `dddff(f)(Gfmfm(fm))KT|MPS|KMH`, `VRBffKT`, `/////KT`; `Some(None)` when not available.
fn wind(group: &str) -> Option<Option<Wind>> {
    let (body, m_per_s_per_unit) = [("KT", M_PER_S_PER_KNOT), ("MPS", 1.0), ("KMH", 1.0 / 3.6)]
        .into_iter()
        .find_map(|(unit, factor)| Some((group.strip_suffix(unit)?, factor)))?;
    if body == "/////" {
        return Some(None);
    }
    if body.len() < 5 || !body.is_char_boundary(3) {
        return None;
    }
    let (direction, speeds) = body.split_at(3);
    let from_deg = match direction {
        "VRB" => None,
        _ => Some(digits(direction, 3).filter(|&d| d <= 360)?),
    };
    let (mean, gust) = match speeds.split_once('G') {
        Some((mean, gust)) => (mean, Some(gust)),
        None => (speeds, None),
    };
    let speed = |text: &str| {
        (2..=3)
            .find_map(|n| digits(text, n))
            .map(|s| s as f32 * m_per_s_per_unit)
    };
    let speed_m_per_s = speed(mean)?;
    let gust_m_per_s = match gust {
        Some(text) => Some(speed(text)?),
        None => None,
    };
    let calm = speed_m_per_s == 0.0;
    Some(Some(Wind {
        from_deg: from_deg.filter(|_| !calm),
        speed_m_per_s,
        gust_m_per_s,
        varying_deg: None,
    }))
}

/// `dndndnVdxdxdx`.
fn wind_variation(group: &str) -> Option<[u32; 2]> {
    let (from, to) = group.split_once('V')?;
    let from = digits(from, 3).filter(|&d| d <= 360)?;
    let to = digits(to, 3).filter(|&d| d <= 360)?;
    Some([from, to])
}

fn ten_km_or_more() -> Visibility {
    Visibility {
        distance_m: 10_000.0,
        bound: Bound::AtLeast,
    }
}

/// `VVVV` in metres (`9999`: 10 km or more; `0000`: less than 50 m; an `NDV` suffix, no
/// directional variation, is allowed), or statute miles `[P|M]n[ n/d]SM`.
fn visibility(group: &str) -> Option<Visibility> {
    if let Some(miles) = group.strip_suffix("SM") {
        return statute_miles(miles);
    }
    let metres = digits(group.strip_suffix("NDV").unwrap_or(group), 4)?;
    Some(match metres {
        9999 => ten_km_or_more(),
        0 => Visibility {
            distance_m: 50.0,
            bound: Bound::LessThan,
        },
        _ => Visibility {
            distance_m: metres as f32,
            bound: Bound::Exact,
        },
    })
}

/// `10`, `1/2`, `1 1/2`, `P6`, `M1/4` statute miles.
fn statute_miles(text: &str) -> Option<Visibility> {
    let (bound, amount) = match text.as_bytes().first()? {
        b'P' => (Bound::AtLeast, &text[1..]),
        b'M' => (Bound::LessThan, &text[1..]),
        _ => (Bound::Exact, text),
    };
    let number = |t: &str| (1..=2).find_map(|n| digits(t, n)).map(|v| v as f32);
    let fraction = |t: &str| {
        let (numerator, denominator) = t.split_once('/')?;
        let denominator = number(denominator).filter(|&d| d > 0.0)?;
        Some(number(numerator)? / denominator)
    };
    let miles = match amount.split_once(' ') {
        Some((whole, part)) => number(whole)? + fraction(part)?,
        None if amount.contains('/') => fraction(amount)?,
        None => number(amount)?,
    };
    Some(Visibility {
        distance_m: miles * METRES_PER_MILE,
        bound,
    })
}

/// `VVVVDv`: the lowest visibility and its direction (one of the eight compass points).
fn directional_visibility(group: &str) -> Option<()> {
    let direction = group.get(4..)?;
    digits(group.get(..4)?, 4)?;
    ["N", "NE", "E", "SE", "S", "SW", "W", "NW"]
        .contains(&direction)
        .then_some(())
}

/// `RDRDR/VRVRVRVRi` and its variants (`R27L/P1500N`, `R09/0600V1000U`, `R24/1200FT`).
fn runway_visual_range(group: &str) -> Option<()> {
    let (runway, range) = group.strip_prefix('R')?.split_once('/')?;
    digits(runway.get(..2)?, 2)?;
    let side_ok = matches!(runway.get(2..)?, "" | "L" | "C" | "R");
    let range_ok = !range.is_empty() && range.bytes().all(|b| b"0123456789PMVFTUDN/".contains(&b));
    (side_ok && range_ok).then_some(())
}

/// `w'w'`: intensity or `VC`, a descriptor and phenomena, e.g. `-SHRA`, `+TSRAGR`, `VCFG`, `BR`.
fn present_weather(group: &str) -> Option<WeatherGroup> {
    let (intensity, rest) = if let Some(rest) = group.strip_prefix('-') {
        (Intensity::Light, rest)
    } else if let Some(rest) = group.strip_prefix('+') {
        (Intensity::Heavy, rest)
    } else if let Some(rest) = group.strip_prefix("VC") {
        (Intensity::Vicinity, rest)
    } else {
        (Intensity::Moderate, group)
    };
    if rest.is_empty() || rest.len() % 2 != 0 || !rest.is_ascii() {
        return None;
    }
    let codes: Vec<&str> = (0..rest.len() / 2)
        .map(|i| &rest[2 * i..2 * i + 2])
        .collect();
    let descriptor = Descriptor::from_code(codes[0]);
    let phenomena = codes[usize::from(descriptor.is_some())..]
        .iter()
        .map(|code| Phenomenon::from_code(code))
        .collect::<Option<Vec<_>>>()?;
    Some(WeatherGroup {
        intensity,
        descriptor,
        phenomena,
    })
}

/// `NsNsNshshshs[CB|TCU|///]`, `VVhshshs`, `SKC`, `CLR`, `NSC`, `NCD`.
fn sky_group(group: &str) -> Option<SkyGroup> {
    if let Some(clear) = ClearSky::from_code(group) {
        return Some(SkyGroup::Clear(clear));
    }
    let height = |text: &str| match text {
        "///" => Some(None),
        _ => digits(text, 3).map(Some),
    };
    if let Some(rest) = group.strip_prefix("VV") {
        return height(rest).map(SkyGroup::VerticalVisibility);
    }
    let cover = Cover::from_code(group.get(..3)?)?;
    let base_hundreds_ft = height(group.get(3..6)?)?;
    let convective = match group.get(6..)? {
        "" | "///" => None,
        code => Some(Convective::from_code(code)?),
    };
    Some(SkyGroup::Cloud(CloudGroup {
        cover,
        base_hundreds_ft,
        convective,
    }))
}

/// `T'T'/T'dT'd` in whole deg C, `M` for minus; either may be missing (`//`, or nothing after the
/// slash).
fn temperatures(group: &str) -> Option<(Option<i32>, Option<i32>)> {
    let (air, dew) = group.split_once('/')?;
    let read = |text: &str| -> Option<Option<i32>> {
        match text {
            "" | "//" => Some(None),
            _ => {
                let (sign, magnitude) = match text.strip_prefix('M') {
                    Some(magnitude) => (-1, magnitude),
                    None => (1, text),
                };
                digits(magnitude, 2).map(|t| Some(sign * t as i32))
            }
        }
    };
    let (air, dew) = (read(air)?, read(dew)?);
    (air.is_some() || dew.is_some()).then_some((air, dew))
}

/// `QPHPHPHPH` in hPa, `APHPHPHPH` in hundredths of inHg; `Some(None)` for `Q////`.
fn pressure(group: &str) -> Option<Option<f32>> {
    let value = group.get(1..)?;
    let hpa_per_unit = match group.as_bytes().first()? {
        b'Q' => 1.0,
        b'A' => HPA_PER_INCH_HG / 100.0,
        _ => return None,
    };
    if value == "////" {
        return Some(None);
    }
    digits(value, 4).map(|v| Some(v as f32 * hpa_per_unit))
}

/// `REw'w'`: recent weather, e.g. `RERA`, `RETSRA`.
fn recent_weather(group: &str) -> Option<()> {
    present_weather(group.strip_prefix("RE")?)
        .filter(|w| w.intensity == Intensity::Moderate)
        .map(|_| ())
}

#[cfg(test)]
mod tests {
    use super::*;

    const EGLL: &str = "EGLL 011750Z 24012KT 9999 FEW012 SCT030 BKN045CB OVC100 18/12 Q1012";

    fn report(text: &str) -> Report {
        parse(text).unwrap_or_else(|e| panic!("{text}: {e}"))
    }

    fn error(text: &str) -> MetarError {
        parse(text).expect_err(text)
    }

    fn cloud(cover: Cover, base: u32, convective: Option<Convective>) -> SkyGroup {
        SkyGroup::Cloud(CloudGroup {
            cover,
            base_hundreds_ft: Some(base),
            convective,
        })
    }

    #[test]
    fn the_issues_report_reads_whole() {
        let r = report(EGLL);
        assert_eq!(r.kind, ReportKind::Metar);
        assert_eq!(r.station, "EGLL");
        assert_eq!(
            r.time,
            ObservationTime {
                day: 1,
                hour: 17,
                minute: 50
            }
        );
        let wind = r.wind.unwrap();
        assert_eq!(wind.from_deg, Some(240));
        assert!((wind.speed_m_per_s - 12.0 * 0.514444).abs() < 1e-5);
        assert_eq!(r.visibility, Some(ten_km_or_more()));
        assert_eq!(
            r.sky,
            [
                cloud(Cover::Few, 12, None),
                cloud(Cover::Scattered, 30, None),
                cloud(Cover::Broken, 45, Some(Convective::Cumulonimbus)),
                cloud(Cover::Overcast, 100, None),
            ]
        );
        assert_eq!((r.temperature_c, r.dew_point_c), (Some(18), Some(12)));
        assert_eq!(r.qnh_hpa, Some(1012.0));
        assert!(!r.cavok && !r.automatic && !r.corrected && r.weather.is_empty());
    }

    #[test]
    fn leading_words_and_modifiers() {
        let r = report("METAR COR EGLL 011750Z AUTO 24012KT 9999 NCD 18/12 Q1012=");
        assert!(r.corrected && r.automatic);
        assert_eq!(r.sky, [SkyGroup::Clear(ClearSky::NoCloudDetected)]);
        let r = report("SPECI KJFK 011751Z COR 00000KT 10SM CLR 22/18 A2992");
        assert_eq!(r.kind, ReportKind::Speci);
        assert!(r.corrected);
        let e = error("EGLL 011750Z NIL");
        assert_eq!((e.group.as_str(), e.column), ("NIL", 14));
    }

    #[test]
    fn wind_groups() {
        let wind = |g: &str| report(&format!("EGLL 011750Z {g} 9999 NSC")).wind;
        let w = wind("24012G25KT").unwrap();
        assert_eq!(w.from_deg, Some(240));
        assert!((w.gust_m_per_s.unwrap() - 25.0 * 0.514444).abs() < 1e-5);
        let w = wind("VRB03KT").unwrap();
        assert_eq!(w.from_deg, None);
        assert!(w.speed_m_per_s > 1.5);
        let w = wind("00000KT").unwrap();
        assert_eq!((w.from_deg, w.speed_m_per_s), (None, 0.0));
        let w = wind("05007MPS").unwrap();
        assert_eq!((w.from_deg, w.speed_m_per_s), (Some(50), 7.0));
        let w = wind("270105KT").unwrap();
        assert!((w.speed_m_per_s - 105.0 * 0.514444).abs() < 1e-4);
        assert_eq!(wind("/////KT"), None);
        let r = report("EGLL 011750Z 24012KT 210V270 9999 NSC");
        assert_eq!(r.wind.unwrap().varying_deg, Some([210, 270]));
    }

    #[test]
    fn visibility_groups() {
        let visibility = |g: &str| report(&format!("KJFK 011751Z 24012KT {g} CLR")).visibility;
        let v = |distance_m: f32, bound| Some(Visibility { distance_m, bound });
        assert_eq!(visibility("0800"), v(800.0, Bound::Exact));
        assert_eq!(visibility("9999NDV"), v(10_000.0, Bound::AtLeast));
        assert_eq!(visibility("0000"), v(50.0, Bound::LessThan));
        assert_eq!(visibility("10SM"), v(10.0 * 1609.344, Bound::Exact));
        assert_eq!(visibility("P6SM"), v(6.0 * 1609.344, Bound::AtLeast));
        assert_eq!(visibility("1/2SM"), v(804.672, Bound::Exact));
        assert_eq!(visibility("M1/4SM"), v(402.336, Bound::LessThan));
        assert_eq!(visibility("1 1/2SM"), v(1.5 * 1609.344, Bound::Exact));
        let r = report("LFPG 011730Z 24012KT CAVOK 18/12 Q1012");
        assert!(r.cavok);
        assert_eq!(r.visibility, Some(ten_km_or_more()));
        assert!(r.sky.is_empty());
        let r = report("LFPG 011730Z 24012KT 4000 1500NE R27L/P1500N R09/0600V1000U BR NSC");
        assert_eq!(r.visibility, v(4000.0, Bound::Exact));
    }

    #[test]
    fn present_weather_groups() {
        let r = report("EGLL 011750Z 24012KT 3000 -RA +TSRAGR VCSH BR FZFG TS SCT010");
        let w = &r.weather;
        assert_eq!(w.len(), 6);
        assert_eq!(
            w[0],
            WeatherGroup {
                intensity: Intensity::Light,
                descriptor: None,
                phenomena: vec![Phenomenon::Rain]
            }
        );
        assert_eq!(w[1].intensity, Intensity::Heavy);
        assert_eq!(w[1].descriptor, Some(Descriptor::Thunderstorm));
        assert_eq!(w[1].phenomena, [Phenomenon::Rain, Phenomenon::Hail]);
        assert_eq!(
            (w[2].intensity, w[2].descriptor),
            (Intensity::Vicinity, Some(Descriptor::Showers))
        );
        assert_eq!(w[3].phenomena, [Phenomenon::Mist]);
        assert_eq!(w[4].descriptor, Some(Descriptor::Freezing));
        assert!(w[5].phenomena.is_empty());
    }

    #[test]
    fn sky_groups() {
        let sky = |g: &str| report(&format!("EGLL 011750Z 24012KT 0200 FG {g}")).sky;
        assert_eq!(sky("VV002"), [SkyGroup::VerticalVisibility(Some(2))]);
        assert_eq!(sky("VV///"), [SkyGroup::VerticalVisibility(None)]);
        assert_eq!(
            sky("SCT030TCU BKN///"),
            [
                cloud(Cover::Scattered, 30, Some(Convective::ToweringCumulus)),
                SkyGroup::Cloud(CloudGroup {
                    cover: Cover::Broken,
                    base_hundreds_ft: None,
                    convective: None
                })
            ]
        );
        assert_eq!(sky("BKN020///"), [cloud(Cover::Broken, 20, None)]);
        assert_eq!(sky("SKC"), [SkyGroup::Clear(ClearSky::SkyClear)]);
    }

    #[test]
    fn temperature_and_pressure_groups() {
        let r = report("EFHK 011750Z 36005KT 9999 FEW020 M02/M05 Q1030");
        assert_eq!((r.temperature_c, r.dew_point_c), (Some(-2), Some(-5)));
        let r = report("EFHK 011750Z 36005KT 9999 FEW020 M02/ A2992");
        assert_eq!((r.temperature_c, r.dew_point_c), (Some(-2), None));
        assert!((r.qnh_hpa.unwrap() - 1013.2) < 0.1);
    }

    #[test]
    fn trend_and_remarks_end_the_report() {
        for tail in [
            "NOSIG",
            "BECMG 25015KT",
            "TEMPO 3000 SHRA",
            "RMK AO2 SLP132",
            "RERA NOSIG",
        ] {
            let r = report(&format!(
                "EGLL 011750Z 24012KT 9999 SCT030 18/12 Q1012 {tail}"
            ));
            assert_eq!(r.sky, [cloud(Cover::Scattered, 30, None)], "{tail}");
        }
    }

    #[test]
    fn bad_groups_are_named_with_their_column() {
        let e = error("EGLL 011750Z 24012KT 9999 FEW012 SCT03O 18/12 Q1012");
        assert_eq!((e.group.as_str(), e.column, e.offset), ("SCT03O", 34, 33));
        assert!(
            e.message.contains("after the cloud group") || e.message.contains("follow the cloud"),
            "{e}"
        );
        let e = error("EGLL 011750Z 24012KT 9999 18/12 FEW012");
        assert_eq!((e.group.as_str(), e.column), ("FEW012", 33));
        assert!(e.message.contains("cloud group out of place"), "{e}");
        let e = error("EGLL 1750Z 24012KT");
        assert_eq!((e.group.as_str(), e.column), ("1750Z", 6));
        assert!(e.message.contains("ddhhmmZ"), "{e}");
        let e = error("EGLL");
        assert!(e.message.contains("ends here"), "{e}");
        assert_eq!(error("   ").column, 1);
        let e = error("EGLL 011750Z 24012KT 9999 XYZ");
        assert_eq!(
            e.to_string(),
            format!("`XYZ` at column 27 of the report: {}", e.message)
        );
    }
}
