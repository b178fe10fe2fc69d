import spiralid


def test_version_is_a_string():
    assert isinstance(spiralid.__version__, str)
    assert spiralid.__version__ != "0.0.0+unknown"
