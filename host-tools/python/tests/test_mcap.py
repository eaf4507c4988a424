"""The CLI's MCAP files read with the Python `mcap` reader and its ROS 2
decoder alone (`mcap-ros2-support`): every topic, `/sensors`, `/gps` and
`/events`, decodes without a decoder of the reader's own."""

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from conftest import cli, cli_json_lines


def decoded(path):
    """Every message of the MCAP file at `path`, decoded, by topic."""
    topics = {}
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _schema, channel, _message, value in reader.iter_decoded_messages():
            topics.setdefault(channel.topic, []).append(value)
    return topics


def test_gps_and_sensors_decode_with_the_ros2_decoder(golden, tmp_path):
    out = tmp_path / "gps.mcap"
    cli("decode", golden["gps"], "-o", out)
    topics = decoded(out)
    rows = cli("decode", golden["gps"]).splitlines()
    assert len(topics["/sensors"]) == len(rows) - 1
    fix = topics["/gps"][0]
    assert fix.frame_id == "gps"
    assert abs(fix.latitude - 52.1234567) < 1e-9
    assert abs(fix.longitude + 1.2345678) < 1e-9
    assert list(fix.position_covariance) == [0.0] * 9


def test_events_decode_with_the_ros2_decoder(golden, tmp_path):
    out = tmp_path / "alert.mcap"
    cli("decode", golden["alert"], "-o", out)
    events = decoded(out)["/events"]
    listed = cli_json_lines("events", golden["alert"], "--json")
    assert [e.name for e in events] == [e["event"] for e in listed]
    first = events[0]
    assert first.level == 3 and first.file == "alert.WBL"
    assert first.message.startswith("alert_on at 0.115 s")
